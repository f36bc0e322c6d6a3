#!/usr/bin/env node
// Builds the workbook's slides: every slides/*.md deck, with its placeholders replaced by
// what the steps measured on this machine, converted by Marp into self-contained HTML (and
// PDF when Chromium is installed) in OUT/slides/, plus OUT/slides/index.html.
//
// usage: node slides/build.mjs [--out DIR] [--bin BUILD_DIR] [--no-pdf] [--rerun] [--quick]
//   --out DIR      where the steps' reports are (OUT/NN_name.json, the tour's) and where
//                  the decks go (OUT/slides/); default: <repo>/out
//   --bin DIR      the CMake build tree with the step programs; default: <repo>/build/release
//   --no-pdf       HTML only
//   --rerun        run every built step program again, even when its report exists
//   --quick        a step program whose report is missing runs without --measure (images,
//                  no tables): for a quick look, never for the tour
//
// Placeholders (HTML comments, one per line):
//   <!-- image: 01_triangle [N | ~text] [h=360] -->   image N (or the first whose path or
//                                                     caption holds text) of the step's report
//   <!-- table: 01_triangle/ID|~text|* [columns=a|b] [rows=N] [dense] -->
//                                                     a measured table (first alternative found)
//   <!-- plot: 01_triangle/N [w=560] [h=330] -->        the report's plot N (tools/plots.py's SVG, as
//                                                     on the report page), at most w x h pixels
//   <!-- fact: 01_triangle/name [| N] -->             one number from the report's facts (also inline;
//                                                     N: decimals)
//   <!-- if: 04_bvh_bench --> A <!-- else --> B <!-- end if -->
//                                                     A when that report exists, else B (may hold
//                                                     whole slides: a slide that says what ran)
//   <!-- machine -->                                  the machine the deck's numbers come from
//   <!-- exercises: 01_triangle -->                  the step's exercise markers as a table
//   <!-- code: 01_triangle NAME|EXERCISE 1.4 [max=N] [nocomments] -->
//                                                     a function from the step's sources
//   <!-- check: 02_box:facts{pixels_disagreeing} == 0 -->
//                                                     removed: a stated outcome that
//                                                     slides/claims.mjs checks against the report
// A step that does not exist (or whose program fails) gets a visible "not built yet" note.
import { spawnSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const root = path.dirname(here);

function parseArgs(argv) {
  const a = { out: path.join(root, "out"), bin: path.join(root, "build", "release"), pdf: true, rerun: false, quick: false };
  for (let i = 0; i < argv.length; ++i) {
    const k = argv[i];
    if (k === "--out") a.out = path.resolve(argv[++i]);
    else if (k === "--bin") a.bin = path.resolve(argv[++i]);
    else if (k === "--no-pdf") a.pdf = false;
    else if (k === "--rerun") a.rerun = true;
    else if (k === "--quick") a.quick = true;
    else {
      console.error(`slides/build.mjs: unknown argument '${k}' (see the comment at the top)`);
      process.exit(2);
    }
  }
  return a;
}

const say = (msg) => console.error(`[slides] ${msg}`);
const esc = (s) => String(s).replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;").replace(/"/g, "&quot;");

// The decks, in teaching order: the numbered steps, then exam practice.
export function deckNames() {
  return fs
    .readdirSync(here)
    .filter((f) => f.endsWith(".md") && f !== "README.md")
    .map((f) => f.slice(0, -3))
    .sort((a, b) => (/^\d/.test(a) ? "0" : "1").concat(a).localeCompare((/^\d/.test(b) ? "0" : "1").concat(b)));
}

// Slides in a Marp Markdown deck: separators "---" outside the front matter and code fences.
export function countSlides(markdown) {
  let lines = markdown.split(/\r?\n/);
  if (lines[0] === "---") {
    const end = lines.indexOf("---", 1);
    lines = lines.slice(end + 1);
  }
  let fence = false, count = 1;
  for (const line of lines) {
    if (/^\s*(```|~~~)/.test(line)) fence = !fence;
    else if (!fence && /^---\s*$/.test(line)) ++count;
  }
  return count;
}

function existingSteps() {
  const dir = path.join(root, "steps");
  return fs.existsSync(dir) ? fs.readdirSync(dir).filter((d) => /^\d\d_/.test(d)).sort() : [];
}

// ---- the steps' reports --------------------------------------------------------------------

const reports = new Map(); // step -> {report, error}

function loadReport(step, args) {
  if (reports.has(step)) return reports.get(step);
  const result = { report: null, error: null };
  reports.set(step, result);
  const json = path.join(args.out, `${step}.json`);
  const program = path.join(args.bin, "steps", step, step);
  // A report that is not a step's own (a benchmark's, e.g. 04_bvh_bench) is read when present.
  if (!fs.existsSync(path.join(root, "steps", step)) && !fs.existsSync(json)) {
    result.error = `steps/${step} does not exist yet`;
    return result;
  }
  if ((args.rerun || !fs.existsSync(json)) && fs.existsSync(program)) {
    const flags = ["--headless", ...(args.quick ? [] : ["--measure"])];
    say(`${step}: running ${path.relative(root, program)} ${flags.join(" ")} (its report was missing)`);
    fs.mkdirSync(args.out, { recursive: true });
    const run = spawnSync(program, [...flags, "--out", path.join(args.out, `${step}.png`), "--report", json], {
      cwd: root,
      stdio: ["ignore", "ignore", "pipe"],
      encoding: "utf8",
      timeout: 300000,
    });
    if (run.status !== 0) {
      const last = (run.stderr || "").trim().split("\n").filter(Boolean).pop() || `exit ${run.status}`;
      result.error = `its program failed: ${last}`;
      say(`${step}: ${result.error}`);
      return result;
    }
  }
  if (!fs.existsSync(json)) {
    result.error = fs.existsSync(program)
      ? `out/${step}.json is missing`
      : `its program is not built yet (build/release/steps/${step}/${step})`;
    return result;
  }
  try {
    result.report = JSON.parse(fs.readFileSync(json, "utf8"));
    result.report._mtime = fs.statSync(json).mtime;
  } catch (e) {
    result.error = `out/${step}.json is not valid JSON (${e.message})`;
  }
  return result;
}

function pending(step, what, error) {
  const notYet = /does not exist yet|not built yet|is missing$/.test(error);
  const head = notYet ? "this step is not built yet" : "this step's output is not available";
  return `<div class="pending">Step ${esc(step)}: ${head}, so its ${esc(what)} is not here (${esc(error)}). Rebuild the slides once it is: <code>cmake --build --preset release --target slides</code>.</div>`;
}

// Numbers as tools/report.py prints them.
function fmt(c) {
  if (typeof c === "number" && !Number.isInteger(c)) {
    if (c === 0) return "0";
    const a = Math.abs(c);
    if (a >= 1e6 || a < 1e-3) return c.toPrecision(3).replace(/\.?0+e/, "e");
    return a >= 100 ? c.toFixed(1) : String(Number(c.toPrecision(4)));
  }
  if (typeof c === "number") return c.toLocaleString("en-US");
  if (typeof c === "boolean") return c ? "yes" : "no";
  return String(c);
}

function parseOptions(words) {
  const opts = {};
  for (const w of words) {
    const m = w.match(/^([a-z]+)=(.*)$/);
    if (m) opts[m[1]] = m[2];
    else opts[w] = true;
  }
  return opts;
}

function findTable(report, alternatives) {
  const tables = report.tables || [];
  for (const alt of alternatives.split("|")) {
    let t = null;
    if (alt === "*") t = tables[0];
    else if (alt.startsWith("~")) {
      const s = alt.slice(1).toLowerCase();
      t = tables.find((x) => x.id.toLowerCase().includes(s) || (x.title || "").toLowerCase().includes(s));
    } else t = tables.find((x) => x.id === alt);
    if (t) return t;
  }
  return null;
}

function tableHtml(step, spec, opts, args) {
  const { report, error } = loadReport(step, args);
  if (!report) return pending(step, "measured table", error);
  const t = findTable(report, spec);
  if (!t) return pending(step, `table '${spec}'`, `no such table in out/${step}.json: the measurements were not run (--measure)`);
  let cols = t.columns.map((_, i) => i);
  if (opts.columns) {
    const wanted = opts.columns.split("|").map((c) => t.columns.indexOf(c));
    if (wanted.every((i) => i >= 0)) cols = wanted;
  }
  const maxRows = Number(opts.rows || 10);
  const rows = t.rows.slice(0, maxRows);
  const dense = opts.dense || cols.length > 6 || rows.length > 7 ? " dense" : "";
  const head = cols.map((i) => `<th>${esc(t.columns[i])}</th>`).join("");
  const body = rows.map((r) => `<tr>${cols.map((i) => `<td>${esc(fmt(r[i]))}</td>`).join("")}</tr>`).join("");
  const more = t.rows.length > rows.length ? ` (first ${rows.length} of ${t.rows.length} rows)` : "";
  const note = t.note ? ` ${esc(t.note)}.` : "";
  return (
    `<div class="measured${dense}" data-table="${esc(step)}/${esc(t.id)}">` +
    `<table><thead><tr>${head}</tr></thead><tbody>${body}</tbody></table>` +
    `<p class="caption">${esc(t.title)}${more}.${note} Measured on ${esc(report.machine || "this machine")}.</p></div>`
  );
}

// The report's plot N (tools/plots.py draws every plot of the tour once, as SVG, for the
// report page and the decks: one figure, one way of placing its labels). Drawn here when
// the tour has not drawn them yet (python3 -m tools.plots OUT, once per build).
let plotsDrawn = false;
function plotFile(step, index, args) {
  const file = path.join(args.out, "plots", `${step}-${index}.svg`);
  if (!fs.existsSync(file) && !plotsDrawn) {
    plotsDrawn = true;
    const python = fs.existsSync("/usr/bin/python3") ? "/usr/bin/python3" : "python3"; // Debian's, with matplotlib
    const run = spawnSync(python, ["-m", "tools.plots", args.out], { cwd: root, encoding: "utf8", timeout: 300000 });
    if (run.status !== 0) say(`python3 -m tools.plots failed (tools/deps.sh report installs matplotlib): ${(run.stderr || "").trim().split("\n").pop()}`);
  }
  return fs.existsSync(file) ? file : null;
}

function plotHtml(step, spec, opts, args, deckDir) {
  const { report, error } = loadReport(step, args);
  if (!report) return pending(step, "plot", error);
  // spec: an index, or ~text found in the plot's table id or title (alternatives with |).
  const plots = report.plots || [];
  let index = -1;
  for (const alt of String(spec || "0").split("|")) {
    if (/^\d+$/.test(alt)) index = Number(alt) < plots.length ? Number(alt) : -1;
    else if (alt === "pareto") index = plots.findIndex((p) => p.pareto);
    else if (alt.startsWith("~")) {
      const t = alt.slice(1).toLowerCase();
      index = plots.findIndex((p) => String(p.table).toLowerCase().includes(t) || String(p.title || "").toLowerCase().includes(t));
    }
    if (index >= 0) break;
  }
  if (index < 0) return `<p class="src">(out/${esc(step)}.json has no plot matching '${esc(spec || "0")}': see its tables.)</p>`;
  const file = plotFile(step, index, args);
  if (!file) return pending(step, "plot", `out/plots/${step}-${index}.svg was not drawn (python3 -m tools.plots; tools/deps.sh report)`);
  const folder = path.join(deckDir, "images", step);
  fs.mkdirSync(folder, { recursive: true });
  fs.copyFileSync(file, path.join(folder, path.basename(file)));
  const W = Number(opts.w || 560), H = Number(opts.h || 330);
  const title = plots[index].title || "";
  return `<div class="figure plot"><img src="images/${esc(step)}/${esc(path.basename(file))}" alt="${esc(title)}" style="max-width:${W}px;max-height:${H}px"></div>`;
}

function imageHtml(step, spec, opts, args, deckDir) {
  const { report, error } = loadReport(step, args);
  const images = report ? report.images || [] : [];
  let img = null;
  if (spec === undefined || spec === "") img = images[0];
  else if (/^\d+$/.test(spec)) img = images[Number(spec)] || images[0];
  else if (spec.startsWith("~")) {
    const s = spec.slice(1).toLowerCase();
    img = images.find((i) => i.path.toLowerCase().includes(s) || (i.caption || "").toLowerCase().includes(s)) || images[0];
  }
  if (!img) return pending(step, "image", error || `out/${step}.json lists no image`);
  const candidates = [path.isAbsolute(img.path) ? img.path : path.join(root, img.path), path.join(args.out, path.basename(img.path))];
  const source = candidates.find((p) => fs.existsSync(p));
  if (!source) return pending(step, "image", `${img.path} is missing`);
  const folder = path.join(deckDir, "images", step);
  fs.mkdirSync(folder, { recursive: true });
  fs.copyFileSync(source, path.join(folder, path.basename(source)));
  const rel = `images/${step}/${path.basename(source)}`;
  const h = Number(opts.h || 360);
  return (
    `<div class="figure"><img src="${esc(rel)}" alt="${esc(img.caption || step)}" style="height:${h}px">` +
    `<p class="caption">${esc(img.caption || "")} (rendered by <code>${esc(step)}</code> on ${esc(report.machine || "this machine")})</p></div>`
  );
}

function factText(step, name, args, decimals) {
  const { report } = loadReport(step, args);
  if (!report || !report.facts || !(name in report.facts)) return `<span class="pending">(${esc(name)}: not measured yet)</span>`;
  const v = report.facts[name];
  return esc(decimals !== undefined && typeof v === "number" ? v.toFixed(Number(decimals)) : fmt(v));
}

function machineHtml(step, args) {
  const steps = step ? [step, ...existingSteps()] : existingSteps();
  for (const s of steps) {
    const { report } = loadReport(s, args);
    if (report && report.machine) {
      const when = report._mtime.toISOString().slice(0, 16).replace("T", " ");
      return `<p class="machine">The numbers in this deck were measured on <b>${esc(report.machine)}</b> (out/${esc(s)}.json, ${when} UTC), when the slides were built.</p>`;
    }
  }
  return `<p class="machine">No step has been measured on this machine yet: run <code>./workbook tour</code>.</p>`;
}

// ---- code excerpts from the steps' sources -------------------------------------------------

function sourceFiles(step) {
  const dir = path.join(root, "steps", step);
  if (!fs.existsSync(dir)) return [];
  const files = [];
  const walk = (d) => {
    for (const e of fs.readdirSync(d, { withFileTypes: true })) {
      const p = path.join(d, e.name);
      if (e.isDirectory()) walk(p);
      else if (/\.(cpp|hpp|h)$/.test(e.name)) files.push(p);
    }
  };
  walk(dir);
  // The exercises' files before the program's main.cpp; headers after sources.
  const rank = (p) => (path.basename(p) === "main.cpp" ? 2 : p.endsWith(".cpp") ? 0 : 1);
  return files.sort((a, b) => rank(a) - rank(b) || a.localeCompare(b));
}

// The block from `start` (a line index) to the brace matching the first "{" at or after it.
function blockEnd(lines, start) {
  let depth = 0, opened = false;
  for (let i = start; i < lines.length; ++i) {
    const code = lines[i].replace(/\/\/.*$/, "").replace(/"(\\.|[^"\\])*"/g, '""').replace(/'(\\.|[^'\\])'/g, "''");
    for (const ch of code) {
      if (ch === "{") { ++depth; opened = true; }
      else if (ch === "}") { --depth; if (opened && depth === 0) return i; }
      else if (ch === ";" && !opened) return -1; // a declaration, not a definition
    }
  }
  return -1;
}

function findDefinition(lines, name) {
  if (/^EXERCISE /.test(name)) {
    const marker = lines.findIndex((l) => l.includes(`// ${name}:`));
    if (marker < 0) return null;
    for (let i = marker + 1; i < Math.min(lines.length, marker + 6); ++i) {
      if (/^\s*(template\b|\/\/)/.test(lines[i]) || !lines[i].includes("(")) continue;
      const end = blockEnd(lines, i);
      if (end >= 0) return [marker, end];
    }
    return null;
  }
  const call = new RegExp(`(^|[\\s*&:~])${name.replace(/[.*+?^${}()[\]\\]/g, "\\$&")}\\s*\\(`);
  for (let i = 0; i < lines.length; ++i) {
    const line = lines[i];
    const m = line.match(call);
    if (!m || /^\s*\/\//.test(line)) continue;
    const before = line.slice(0, m.index);
    if (/^\s{5,}/.test(line) || /\b(return|if|while|for|else|case)\b|[=(]/.test(before)) continue;
    const end = blockEnd(lines, i);
    if (end < 0) continue;
    let start = i;
    if (start > 0 && /^\s*template\s*</.test(lines[start - 1])) --start;
    // The comment block right above (the exercise marker, the why) when it is short;
    // of a longer one only its exercise marker line.
    let top = start;
    while (top > 0 && /^\s*\/\//.test(lines[top - 1])) --top;
    if (start - top <= 3) return [top, end];
    const marker = lines.slice(top, start).findIndex((l) => /EXERCISE\s+\d/.test(l));
    return marker < 0 ? [start, end] : [top + marker, end, top + marker];
  }
  return null;
}

// The first line after `from` that is not a comment: where the definition starts.
function nextCode(lines, from) {
  let i = from;
  while (i < lines.length && /^\s*\/\//.test(lines[i])) ++i;
  return i;
}

function codeExcerpt(step, names, opts) {
  for (const name of names.split("|").map((s) => s.trim()).filter(Boolean)) {
    for (const file of sourceFiles(step)) {
      const lines = fs.readFileSync(file, "utf8").split("\n");
      const found = findDefinition(lines, name);
      if (!found) continue;
      // found: [first, last] or [marker, last, marker] when only the marker line is kept.
      let body = found.length === 3 ? [lines[found[0]]].concat(lines.slice(nextCode(lines, found[0]), found[1] + 1)) : lines.slice(found[0], found[1] + 1);
      body = body.filter((l) => !/\/\/\s*(BEGIN|END) SOLUTION/.test(l));
      // nocomments: drop comment lines, but keep the exercise marker and its wrapped "points)".
      const wrapped = /EXERCISE/.test(body[0]) && !/points?\)/.test(body[0]);
      if (opts.nocomments) body = body.filter((l, i) => i === 0 || (i === 1 && wrapped) || !/^\s*\/\/(?!\s*EXERCISE)/.test(l));
      const indent = Math.min(...body.filter((l) => l.trim()).map((l) => l.match(/^\s*/)[0].length));
      body = body.map((l) => l.slice(indent));
      const max = Number(opts.max || 16);
      if (body.length > max) {
        const rest = body.length - max + 1;
        body = body.slice(0, max - 1).concat([`    // ... ${rest} more lines in ${path.basename(file)}`]);
      }
      const rel = path.relative(root, file);
      return `\`\`\`cpp\n${body.join("\n")}\n\`\`\`\n<p class="src">from ${esc(rel)} (<code>${esc(name)}</code>), as built</p>`;
    }
  }
  const exists = fs.existsSync(path.join(root, "steps", step));
  return `<p class="src">${exists ? `The excerpt (${esc(names)}) is not in steps/${esc(step)}'s sources under that name: read the step's sources.` : `The code excerpt appears here once steps/${esc(step)} exists.`}</p>`;
}

// The exercise markers "// EXERCISE N.M: what (P points)" in the step's sources, as a table.
function exercisesHtml(step) {
  const rows = [];
  for (const file of sourceFiles(step)) {
    const lines = fs.readFileSync(file, "utf8").split("\n");
    for (let i = 0; i < lines.length; ++i) {
      if (!/\/\/\s*EXERCISE\s+\d+\.\d+:/.test(lines[i])) continue;
      // The marker, joined with the comment line after it when its "(N points)" wrapped.
      let line = lines[i];
      if (!/\(\d+\s+points?\)/.test(line) && /^\s*\/\//.test(lines[i + 1] || "")) line += " " + lines[i + 1].replace(/^\s*\/\/\s*/, "");
      const m = line.match(/\/\/\s*EXERCISE\s+(\d+)\.(\d+):\s*(.*?)\s*\((\d+)\s+points?\)/);
      if (m) rows.push({ major: Number(m[1]), minor: Number(m[2]), what: m[3], points: Number(m[4]), file: path.basename(file) });
    }
  }
  if (!rows.length) return pending(step, "exercise list", fs.existsSync(path.join(root, "steps", step)) ? "no exercise markers found" : `steps/${step} does not exist yet`);
  rows.sort((a, b) => a.major - b.major || a.minor - b.minor);
  const dense = rows.length > 7 ? " dense" : "";
  const body = rows.map((r) => `<tr><td>${r.major}.${r.minor}</td><td>${r.points}</td><td style="text-align:left">${esc(r.what)}</td><td style="text-align:left"><code>${esc(r.file)}</code></td></tr>`).join("");
  const total = rows.reduce((a, r) => a + r.points, 0);
  return `<div class="measured exercises${dense}"><table><thead><tr><th>exercise</th><th>points</th><th>what</th><th>file</th></tr></thead><tbody>${body}</tbody></table><p class="caption">${rows.length} exercises, ${total} points, read from the markers in steps/${esc(step)}/ when the slides were built.</p></div>`;
}

// ---- decks ---------------------------------------------------------------------------------

function expand(markdown, deck, args, deckDir) {
  const deckStep = /^\d\d_/.test(deck) ? deck : null;
  // Stated outcomes' checks (slides/claims.mjs reads them) are for the test, not the notes.
  markdown = markdown.replace(/^[ \t]*<!--\s*check:.*?-->[ \t]*\r?\n/gm, "");
  // What ran decides: "<!-- if: STEP --> A <!-- else --> B <!-- end if -->".
  markdown = markdown.replace(/<!--\s*if:\s*(\S+)\s*-->([\s\S]*?)(?:<!--\s*else\s*-->([\s\S]*?))?<!--\s*end if\s*-->[ \t]*\r?\n?/g,
    (_, step, then, otherwise) => (loadReport(step, args).report ? then : otherwise || ""));
  // A fact may stand inside a sentence: "<!-- fact: 02_box/random_rays --> rays".
  markdown = markdown.replace(/<!--\s*fact:?\s*(\d\d_[A-Za-z0-9_]+)\/(\S+?)(?:\s*\|\s*(\d+))?\s*-->/g, (_, step, name, decimals) => factText(step, name, args, decimals));
  return markdown.replace(/^[ \t]*<!--\s*(image|table|plot|fact|machine|code|exercises):?\s*(.*?)\s*-->[ \t]*$/gm, (_, kind, rest) => {
    const words = [...rest.matchAll(/(\w+)="([^"]*)"|(\S+)/g)].map((m) => (m[3] !== undefined ? m[3] : `${m[1]}=${m[2]}`));
    if (kind === "machine") return machineHtml(deckStep, args);
    if (kind === "exercises") return exercisesHtml(words[0]);
    if (kind === "code") {
      // code: STEP NAME|NAME... [options]; names may contain a space ("EXERCISE 1.4").
      const m = rest.match(/^(\S+)\s+(.*?)((\s+(max=\d+|nocomments))*)$/);
      if (!m) return `<p class="src">(bad code placeholder)</p>`;
      return codeExcerpt(m[1], m[2], parseOptions(m[3].trim().split(/\s+/).filter(Boolean)));
    }
    const [target, ...optionWords] = words;
    const opts = parseOptions(optionWords);
    const slash = target.indexOf("/");
    const step = slash < 0 ? target : target.slice(0, slash);
    const spec = slash < 0 ? "" : target.slice(slash + 1);
    if (kind === "image") return imageHtml(step, spec || optionWords.find((w) => !w.includes("=")), opts, args, deckDir);
    if (kind === "table") {
      // STEP/ID,STEP2/ID2: the first report that has its table (a benchmark's, else the tour's).
      const targets = target.split(",");
      for (const t of targets.slice(0, -1)) {
        const [s2, id2] = t.split("/");
        const { report } = loadReport(s2, args);
        if (report && findTable(report, id2 || "*")) return tableHtml(s2, id2 || "*", opts, args);
      }
      const last = targets[targets.length - 1].split("/");
      return tableHtml(last[0], last[1] || "*", opts, args);
    }
    if (kind === "plot") return plotHtml(step, spec, opts, args, deckDir);
    return factText(step, spec, args);
  });
}

function title(markdown, fallback) {
  const m = markdown.match(/^#\s+(.+)$/m);
  return m ? m[1].replace(/<[^>]+>/g, "").trim() : fallback;
}

function indexHtml(decks, deckDir) {
  const rows = decks
    .map((d) => {
      const pdf = fs.existsSync(path.join(deckDir, `${d.name}.pdf`)) ? ` · <a href="${d.name}.pdf">PDF</a>` : "";
      const png = fs.existsSync(path.join(deckDir, `${d.name}-slide1.png`))
        ? `<img src="${d.name}-slide1.png" alt="">`
        : "";
      const status = d.notes.length ? `<span class=warn>${esc(d.notes.join("; "))}</span>` : "measured on this machine";
      return `<tr><td>${png}</td><td><a href="${d.name}.html"><b>${esc(d.title)}</b></a>${pdf}<br><small>${d.slides} slides · ${status}</small></td></tr>`;
    })
    .join("\n");
  return `<!doctype html><html><head><meta charset=utf-8><title>Boxes workbook: the slides</title>
<style>body{font-family:sans-serif;max-width:960px;margin:2em auto;color:#222}td{padding:6px 12px;vertical-align:top}
img{width:256px;border:1px solid #ccc}.warn{color:#9a6700}</style></head><body>
<h1>Boxes workbook: the slides</h1>
<p>One deck per step, built from <code>slides/*.md</code> with the steps' own images and measurements.
Open a deck and press <kbd>P</kbd> for the presenter view with the speaker notes, <kbd>F</kbd> for full screen.
<a href="../index.html">The tour's report</a>.</p>
<table>
${rows}
</table></body></html>
`;
}

function marp(files, extra) {
  const bin = path.join(here, "node_modules", ".bin", "marp");
  const run = spawnSync(
    bin,
    ["--no-stdin", "--html", "--allow-local-files", "--theme-set", path.join(here, "theme.css"), ...extra, "--", ...files],
    { stdio: ["ignore", "pipe", "pipe"], encoding: "utf8", env: process.env, timeout: 600000 },
  );
  if (run.status !== 0) {
    process.stderr.write(run.stdout + run.stderr);
    return false;
  }
  return true;
}

export function chromiumPath() {
  for (const p of [process.env.CHROME_PATH, "/usr/bin/chromium", "/usr/bin/chromium-browser"]) {
    if (p && fs.existsSync(p)) return p;
  }
  return null;
}

function main() {
  const args = parseArgs(process.argv.slice(2));
  if (!fs.existsSync(path.join(here, "node_modules", ".bin", "marp"))) {
    say("Marp is not installed: run tools/deps.sh slides (npm ci in slides/)");
    process.exit(1);
  }
  const deckDir = path.join(args.out, "slides");
  fs.mkdirSync(deckDir, { recursive: true });
  fs.rmSync(path.join(deckDir, "images"), { recursive: true, force: true });
  const decks = [];
  for (const name of deckNames()) {
    const source = fs.readFileSync(path.join(here, `${name}.md`), "utf8");
    const built = expand(source, name, args, deckDir);
    fs.writeFileSync(path.join(deckDir, `${name}.md`), built);
    const notes = [];
    if (/^\d\d_/.test(name)) {
      const { report, error } = loadReport(name, args);
      if (!report) notes.push(`not built yet: ${error}`);
      else if (!(report.tables || []).length) notes.push("no measurements in its report");
    }
    decks.push({ name, title: title(source, name), slides: countSlides(built), notes });
  }
  const files = decks.map((d) => path.join(deckDir, `${d.name}.md`));
  const started = Date.now();
  if (!marp(files, [])) process.exit(1);
  say(`wrote ${decks.length} HTML decks into ${path.relative(root, deckDir) || deckDir} (${((Date.now() - started) / 1000).toFixed(1)} s)`);
  const chrome = chromiumPath();
  if (args.pdf && chrome) {
    process.env.CHROME_PATH = chrome;
    if (process.getuid && process.getuid() === 0) process.env.CHROME_NO_SANDBOX = "1";
    const t0 = Date.now();
    if (!marp(files, ["--pdf"])) process.exit(1);
    say(`wrote ${decks.length} PDF decks (${((Date.now() - t0) / 1000).toFixed(1)} s)`);
  } else if (args.pdf) {
    say("no Chromium (Debian package chromium): HTML only, no PDF");
  }
  fs.writeFileSync(path.join(deckDir, "index.html"), indexHtml(decks, deckDir));
  fs.writeFileSync(path.join(deckDir, "decks.json"), JSON.stringify(decks, null, 1));
  say(`open ${path.join(path.relative(root, deckDir) || deckDir, "index.html")}`);
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) main();
