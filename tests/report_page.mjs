#!/usr/bin/env node
// The tour's report page in a real browser: opens OUT/index.html in headless Chromium with
// no network and checks, for every step the tour measured (OUT/NN_name.json), that its
// section opens with the summary of this run, lists the README's "What to look for" points
// each with its mark (agrees / disagrees / not checked; what a disagreement means is
// slides/claims.mjs's to say), links to the step's README, its
// deck and docs/measuring.md (each target present), shows every image (none broken), and
// puts a takeaway under every table and plot. Saves OUT/report-page.png (the first screen)
// and OUT/report-step.png (the first step's section) for a person to look at.
//
// usage: node tests/report_page.mjs [--out DIR]
// The page is the tour's; when it is missing but the step reports are there, it is written
// first (python3 -m tools.plots, slides/claims.mjs --json, python3 -m tools.report).
// Exit 0 when every step passes, 1 when one fails, 77 (ctest's skip) without Chromium, the
// npm packages or any step report (run ./workbook tour).
import { spawnSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const root = path.dirname(here);
const SKIP = 77;
let out = path.join(root, "out");
for (let i = 2; i < process.argv.length; ++i) {
  if (process.argv[i] === "--out") out = path.resolve(process.argv[++i]);
  else {
    console.error(`tests/report_page.mjs: unknown argument '${process.argv[i]}'`);
    process.exit(2);
  }
}

const chromium = [process.env.CHROME_PATH, "/usr/bin/chromium", "/usr/bin/chromium-browser"].find((p) => p && fs.existsSync(p));
if (!chromium) {
  console.log("SKIP: no Chromium (Debian package chromium); tools/deps.sh slides installs it");
  process.exit(SKIP);
}
const playwrightDir = path.join(root, "slides", "node_modules", "playwright-core");
if (!fs.existsSync(playwrightDir)) {
  console.log("SKIP: playwright-core is missing; tools/deps.sh slides runs npm ci in slides/");
  process.exit(SKIP);
}
const steps = fs.existsSync(out) ? fs.readdirSync(out).filter((f) => /^\d\d_[a-z0-9_]+\.json$/.test(f)).map((f) => f.slice(0, -5)).filter((s) => fs.existsSync(path.join(root, "steps", s))).sort() : [];
if (!steps.length) {
  console.log(`SKIP: no step report in ${out} (run ./workbook tour)`);
  process.exit(SKIP);
}
const page = path.join(out, "index.html");
if (!fs.existsSync(page)) {
  console.log(`${path.relative(root, page)} is missing: writing it from the step reports`);
  const python = fs.existsSync("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  for (const [cmd, args] of [[python, ["-m", "tools.plots", out]], [process.execPath, [path.join(root, "slides", "claims.mjs"), "--out", out, "--json", path.join(out, "claims.json")]], [python, ["-m", "tools.report", out]]]) {
    const run = spawnSync(cmd, args, { cwd: root, encoding: "utf8" });
    if (run.status !== 0 && !(cmd === process.execPath && run.status === 1)) {
      console.log(`FAIL: ${path.basename(cmd)} ${args.join(" ")}: exit ${run.status}\n${run.stdout}${run.stderr}`);
      process.exit(1);
    }
  }
}

const { chromium: playwright } = await import(pathToFileURL(path.join(playwrightDir, "index.mjs")).href);
const profile = fs.mkdtempSync(path.join(fs.existsSync(path.join(root, "build")) ? path.join(root, "build") : out, "report-chromium-"));
const context = await playwright.launchPersistentContext(profile, {
  executablePath: chromium,
  headless: true,
  args: ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update", "--no-first-run"],
  viewport: { width: 1280, height: 900 },
});
const failures = [];
const results = [];
try {
  const tab = await context.newPage();
  tab.on("pageerror", (e) => failures.push(`page error: ${e.message}`));
  tab.on("request", (r) => {
    if (!/^(file|data|blob|about):/.test(r.url())) failures.push(`network request: ${r.url()} (the page must work offline)`);
  });
  await tab.goto(pathToFileURL(page).href, { waitUntil: "load" });
  await tab.waitForFunction(() => [...document.images].every((i) => i.complete), null, { timeout: 30000 }).catch(() => {});
  for (const step of steps) {
    const report = JSON.parse(fs.readFileSync(path.join(out, `${step}.json`), "utf8"));
    const facts = await tab.evaluate((id) => {
      const h = document.getElementById(id);
      const section = h && h.closest("section");
      if (!section) return null;
      const text = (sel) => [...section.querySelectorAll(sel)].map((e) => e.textContent.trim());
      const href = (sel) => section.querySelector(sel)?.getAttribute("href") || null;
      return {
        summary: (section.querySelector("p.summary:not(.missing)")?.textContent || "").trim(),
        points: [...section.querySelectorAll("ul.points > li")].map((li) => ({
          mark: (li.querySelector(".mark")?.textContent || "").trim(),
          status: [...li.classList].find((c) => c !== "point") || "",
          text: (li.querySelector(".text")?.textContent || "").trim(),
        })),
        links: { readme: href("a.readme"), deck: href("a.deck"), measuring: href("a.measuring") },
        images: [...section.querySelectorAll("img")].map((i) => ({ src: i.getAttribute("src"), ok: i.complete && i.naturalWidth > 0 && i.naturalHeight > 0 })),
        tables: [...section.querySelectorAll("div.table")].map((d) => ({ id: d.dataset.table, has: !!d.querySelector(".takeaway") })),
        plots: [...section.querySelectorAll("figure.plot")].map((f) => ({ index: f.dataset.plot, has: !!f.querySelector(".takeaway") })),
        headings: text("h3"),
      };
    }, step);
    const bad = [];
    if (!facts) {
      results.push({ step, bad: [`no section with id '${step}'`] });
      continue;
    }
    if (facts.summary.split(/[.!?](\s|$)/).filter((s) => s && s.trim().length > 3).length < 2)
      bad.push(`no summary of two sentences or more (got '${facts.summary.slice(0, 80)}')`);
    if (!facts.points.length) bad.push("no 'What to look for' points");
    for (const p of facts.points) {
      if (!/agrees|disagrees|not checked|not measured|cannot be read/.test(p.mark) || !p.status) bad.push(`a point without its mark: '${p.text.slice(0, 60)}'`);
      // A point this run disagrees with is marked so (slides/claims.mjs fails on it); one
      // whose check cannot be read is the page's fault.
      if (p.status === "error") bad.push(`a point's check cannot be read: '${p.text.slice(0, 60)}'`);
    }
    if (!facts.points.some((p) => p.status === "agree")) bad.push("no point is checked against this run");
    for (const [kind, href] of Object.entries(facts.links)) {
      if (!href) bad.push(`no link to the ${kind}`);
      else if (!fs.existsSync(path.resolve(out, decodeURIComponent(href.split("#")[0])))) bad.push(`the ${kind} link goes nowhere: ${href}`);
    }
    for (const img of facts.images) if (!img.ok) bad.push(`broken image: ${img.src}`);
    const wantImages = (report.images || []).length + (report.plots || []).length;
    if (facts.images.length < wantImages) bad.push(`${facts.images.length} images on the page, the report has ${wantImages} (images and plots)`);
    const tablesWithout = facts.tables.filter((t) => !t.has).map((t) => t.id);
    if (facts.tables.length !== (report.tables || []).length) bad.push(`${facts.tables.length} tables on the page, ${(report.tables || []).length} in the report`);
    if (tablesWithout.length) bad.push(`tables without a takeaway (steps/${step}/README.md, <!-- takeaway ID: ... -->): ${tablesWithout.join(", ")}`);
    const plotsWithout = facts.plots.filter((p) => !p.has).map((p) => `plot ${p.index}`);
    if (plotsWithout.length) bad.push(`plots without a takeaway (<!-- takeaway plot N: ... -->): ${plotsWithout.join(", ")}`);
    results.push({ step, bad, counts: `${facts.points.length} points (${facts.points.filter((p) => p.status === "agree").length} agree), ${facts.images.length} images, ${facts.tables.length} tables, ${facts.plots.length} plots` });
  }
  await tab.screenshot({ path: path.join(out, "report-page.png") });
  const first = await tab.$(`section.step`);
  if (first) await first.screenshot({ path: path.join(out, "report-step.png") });
  await tab.close();
} finally {
  await context.close();
  fs.rmSync(profile, { recursive: true, force: true });
}

let failed = failures.length ? 1 : 0;
for (const f of failures.slice(0, 10)) console.log(`FAIL page: ${f}`);
for (const r of results) {
  console.log(`${r.bad.length ? "FAIL" : "ok  "} ${r.step}${r.counts ? `: ${r.counts}` : ""}`);
  for (const b of r.bad.slice(0, 12)) console.log(`       ${b}`);
  if (r.bad.length) ++failed;
}
console.log(`${results.length - (failed - (failures.length ? 1 : 0))} of ${results.length} steps pass; screenshots: ${path.relative(root, path.join(out, "report-page.png"))}, report-step.png`);
process.exit(failed ? 1 : 0);
