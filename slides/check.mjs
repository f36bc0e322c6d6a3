#!/usr/bin/env node
// The slides' browser test: builds the decks (slides/build.mjs), opens every one in headless
// Chromium and checks that it loads without console errors or network requests, that its
// slide count matches the Markdown, that every image resolves with a non-zero size, that
// every formula rendered (no raw $...$, no MathJax error) and that no slide's content
// overflows its frame, and that every stated outcome agrees with its report (claims.mjs). Saves OUT/slides/NAME-slide1.png (the first slide) and
// OUT/slides/NAME-formula.png (the first slide with a formula) for a person to look at.
//
// usage: node slides/check.mjs [--out DIR] [--bin BUILD_DIR] [--no-build] [--no-pdf] [--every-slide]
// (--every-slide: also a PNG of every slide in OUT/slides/all/)
// Exit 0 when every deck passes, 1 when one fails, 77 (ctest's skip) when Chromium or the
// npm packages are missing (tools/deps.sh slides installs both).
import { spawnSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath, pathToFileURL } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const root = path.dirname(here);
const SKIP = 77;

const args = { out: path.join(root, "out"), bin: path.join(root, "build", "release"), build: true, pdf: true };
for (let i = 2; i < process.argv.length; ++i) {
  const k = process.argv[i];
  if (k === "--out") args.out = path.resolve(process.argv[++i]);
  else if (k === "--bin") args.bin = path.resolve(process.argv[++i]);
  else if (k === "--no-build") args.build = false;
  else if (k === "--no-pdf") args.pdf = false;
  else if (k === "--every-slide") args.every = true;
  else {
    console.error(`slides/check.mjs: unknown argument '${k}'`);
    process.exit(2);
  }
}

const chromium = [process.env.CHROME_PATH, "/usr/bin/chromium", "/usr/bin/chromium-browser"].find((p) => p && fs.existsSync(p));
if (!chromium) {
  console.log("SKIP: no Chromium (Debian package chromium); tools/deps.sh slides installs it");
  process.exit(SKIP);
}
if (!fs.existsSync(path.join(here, "node_modules", "playwright-core")) || !fs.existsSync(path.join(here, "node_modules", ".bin", "marp"))) {
  console.log("SKIP: the slides' npm packages are missing; tools/deps.sh slides runs npm ci in slides/");
  process.exit(SKIP);
}
const { countSlides, deckNames } = await import("./build.mjs");
const { chromium: playwright } = await import("playwright-core");

const started = Date.now();
if (args.build) {
  const build = spawnSync(process.execPath, [path.join(here, "build.mjs"), "--out", args.out, "--bin", args.bin, ...(args.pdf ? [] : ["--no-pdf"])], {
    stdio: "inherit",
  });
  if (build.status !== 0) {
    console.log("FAIL: slides/build.mjs failed");
    process.exit(1);
  }
}
const deckDir = path.join(args.out, "slides");
if (args.every) fs.mkdirSync(path.join(deckDir, "all"), { recursive: true });

// Runs in the page: facts about the active slide.
function inspectSlide() {
  const svg = document.querySelector("svg[data-marpit-svg].bespoke-marp-active") || document.querySelector("[data-bespoke-marp-active] svg, svg[data-bespoke-marp-active]");
  const section = (svg || document).querySelector("section");
  if (!section) return { error: "no active slide" };
  const frame = section.getBoundingClientRect();
  const tolerance = 1.5;
  const overflowing = [];
  if (section.scrollHeight > section.clientHeight + 1 || section.scrollWidth > section.clientWidth + 1)
    overflowing.push(`the slide scrolls (${section.scrollWidth}x${section.scrollHeight} in ${section.clientWidth}x${section.clientHeight})`);
  for (const el of section.querySelectorAll("*")) {
    const r = el.getBoundingClientRect();
    if (r.width === 0 && r.height === 0) continue;
    if (r.bottom > frame.bottom + tolerance || r.right > frame.right + tolerance || r.top < frame.top - tolerance || r.left < frame.left - tolerance) {
      const text = (el.textContent || el.getAttribute("src") || "").trim().slice(0, 50);
      overflowing.push(`<${el.tagName.toLowerCase()}> "${text}" leaves the frame`);
      break;
    }
    if (["PRE", "TABLE", "DIV", "P"].includes(el.tagName) && el.scrollWidth > el.clientWidth + 2 && getComputedStyle(el).overflowX !== "visible")
      overflowing.push(`<${el.tagName.toLowerCase()}> "${(el.textContent || "").trim().slice(0, 40)}" is cut on the right`);
  }
  // Raw TeX left in the text, outside code and rendered math.
  const clone = section.cloneNode(true);
  for (const el of clone.querySelectorAll("pre, code, mjx-container, svg, script, style")) el.remove();
  const text = clone.textContent;
  const rawMath = (text.match(/\$\$?[^$\n]{1,80}\$\$?|\\(frac|cdot|times|le|ge|begin)\b/) || [null])[0];
  const mathErrors = section.querySelectorAll('mjx-merror, [data-mml-node="merror"], [data-mjx-error]').length + (/Math input error/.test(section.textContent) ? 1 : 0);
  return {
    overflowing,
    rawMath,
    mathErrors,
    formulas: section.querySelectorAll("mjx-container").length,
    displayFormulas: section.querySelectorAll('mjx-container[display="true"]').length,
    images: section.querySelectorAll("img").length,
  };
}

// Chromium's profile in the build folder, not the shared /tmp: an interrupted check leaves it
// in the clone, and the next check starts it afresh.
const profile = path.join(args.bin, "slides-chromium-profile");
fs.rmSync(profile, { recursive: true, force: true });
fs.mkdirSync(profile, { recursive: true });
const context = await playwright.launchPersistentContext(profile, {
  executablePath: chromium,
  headless: true,
  args: ["--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update", "--no-first-run"],
  viewport: { width: 1280, height: 720 },
});
const results = [];
try {
  for (const name of deckNames()) {
    const failures = [];
    const html = path.join(deckDir, `${name}.html`);
    if (!fs.existsSync(html)) {
      results.push({ name, failures: [`${path.relative(root, html)} was not built`] });
      continue;
    }
    const page = await context.newPage();
    page.on("console", (m) => m.type() === "error" && failures.push(`console error: ${m.text()}`));
    page.on("pageerror", (e) => failures.push(`page error: ${e.message}`));
    page.on("requestfailed", (r) => failures.push(`request failed: ${r.url()} (${r.failure()?.errorText})`));
    page.on("request", (r) => {
      if (!/^(file|data|blob|about):/.test(r.url())) failures.push(`network request: ${r.url()} (a deck must need no network)`);
    });
    await page.goto(pathToFileURL(html).href, { waitUntil: "load" });
    // The on-screen controls would cover the screenshots' bottom.
    await page.addStyleTag({ content: ".bespoke-marp-osc { display: none !important; }" });
    await page.waitForFunction(() => [...document.images].every((i) => i.complete), null, { timeout: 15000 }).catch(() => {});

    // The deck as built (slides/build.mjs drops the slides of what did not run).
    const expected = countSlides(fs.readFileSync(path.join(deckDir, `${name}.md`), "utf8"));
    const slides = await page.evaluate(() => document.querySelectorAll("svg[data-marpit-svg]").length);
    if (slides !== expected) failures.push(`${slides} slides in the HTML, ${expected} in ${path.relative(root, deckDir)}/${name}.md`);
    const badImages = await page.evaluate(() =>
      [...document.images].filter((i) => !i.complete || i.naturalWidth === 0 || i.naturalHeight === 0).map((i) => i.getAttribute("src")),
    );
    for (const src of badImages) failures.push(`image does not load: ${src}`);
    const imageCount = await page.evaluate(() => document.images.length);
    const tableCount = await page.evaluate(() => document.querySelectorAll(".measured:not(.exercises) table").length);

    let formulaSlide = 0, anyFormulaSlide = 0, formulas = 0;
    for (let i = 1; i <= slides; ++i) {
      await page.evaluate((n) => (location.hash = `#${n}`), i);
      await page.waitForFunction((n) => {
        const active = document.querySelector(".bespoke-marp-active, [data-bespoke-marp-active]");
        return active && [...document.querySelectorAll("svg[data-marpit-svg]")].indexOf(active.closest("svg[data-marpit-svg]") || active) === n - 1;
      }, i, { timeout: 5000 }).catch(() => failures.push(`slide ${i}: could not navigate to it`));
      const facts = await page.evaluate(inspectSlide);
      if (facts.error) failures.push(`slide ${i}: ${facts.error}`);
      for (const o of facts.overflowing || []) failures.push(`slide ${i}: ${o}`);
      if (facts.rawMath) failures.push(`slide ${i}: formula not rendered: ${facts.rawMath}`);
      if (facts.mathErrors) failures.push(`slide ${i}: ${facts.mathErrors} MathJax error(s)`);
      formulas += facts.formulas || 0;
      if (args.every) await page.screenshot({ path: path.join(deckDir, "all", `${name}-${String(i).padStart(2, "0")}.png`) });
      if (i === 1) await page.screenshot({ path: path.join(deckDir, `${name}-slide1.png`) });
      // The first slide with a displayed formula (else the first with any formula).
      if (!formulaSlide && facts.displayFormulas > 0) {
        formulaSlide = i;
        await page.screenshot({ path: path.join(deckDir, `${name}-formula.png`) });
      }
      if (!anyFormulaSlide && facts.formulas > 0) anyFormulaSlide = i;
    }
    if (!formulaSlide && anyFormulaSlide) {
      formulaSlide = anyFormulaSlide;
      await page.evaluate((n) => (location.hash = `#${n}`), formulaSlide);
      await page.waitForTimeout(300);
      await page.screenshot({ path: path.join(deckDir, `${name}-formula.png`) });
    }
    if (!formulas) failures.push("no formula rendered anywhere in the deck");
    // Once a step exists and has been run, its deck must show its picture and its numbers.
    const reportPath = path.join(args.out, `${name}.json`);
    if (/^\d\d_/.test(name) && fs.existsSync(path.join(root, "steps", name)) && fs.existsSync(reportPath)) {
      const report = JSON.parse(fs.readFileSync(reportPath, "utf8"));
      if ((report.images || []).length && imageCount === 0) failures.push("the step rendered images, but the deck shows none");
      if ((report.tables || []).length && tableCount === 0) failures.push("the step measured tables, but the deck shows none");
    }
    const pdf = path.join(deckDir, `${name}.pdf`);
    if (args.pdf && !(fs.existsSync(pdf) && fs.statSync(pdf).size > 1000)) failures.push(`${path.relative(root, pdf)} missing or empty`);
    results.push({ name, failures, slides, imageCount, tableCount, formulas, formulaSlide });
    await page.close();
  }
} finally {
  await context.close();
  fs.rmSync(profile, { recursive: true, force: true });
}

// Every stated outcome of the decks and READMEs against the reports just used.
const claims = spawnSync(process.execPath, [path.join(here, "claims.mjs"), "--out", args.out], { encoding: "utf8" });
process.stdout.write(claims.stdout + claims.stderr);
if (claims.status === 1) results.push({ name: "stated outcomes", failures: ["slides/claims.mjs: a stated outcome disagrees with its report (above)"] });

let failed = 0;
for (const r of results) {
  const status = r.failures.length ? "FAIL" : "ok  ";
  if (r.failures.length) ++failed;
  const counts = r.slides === undefined ? "" : ` ${r.slides} slides, ${r.imageCount} images, ${r.tableCount} measured tables, ${r.formulas} formulas (screenshots: ${r.name}-slide1.png, ${r.name}-formula.png = slide ${r.formulaSlide})`;
  console.log(`${status} ${r.name}:${counts}`);
  for (const f of r.failures.slice(0, 12)) console.log(`       ${f}`);
}
console.log(`slides: ${((Date.now() - started) / 1000).toFixed(1)} s, screenshots in ${path.relative(root, deckDir) || deckDir}`);
console.log(`${results.length - failed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
