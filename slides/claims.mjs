#!/usr/bin/env node
// Checks that what the decks and READMEs state about a measured outcome agrees with the
// steps' reports (OUT/NN_name.json, the tour's). A stated outcome carries a comment beside
// the sentence, one comparison each:
//
//   <!-- check: 02_box:method_disagreement[random rays]{hit/miss differ} > 0 -->
//   <!-- check: 03_aabb:facts{pretest_pixels_differing} == 0 -->
//   <!-- check: 03_aabb:slab_accuracy[robust]{ns/test} > 1.2 * 03_aabb:slab_accuracy[naive (slide]{ns/test} -->
//
// A reference is STEP:TABLE[ROW]{COLUMN}: the table with that id, the one row whose cells
// (joined by spaces) contain ROW (of several, the one where ROW is whole cells; "A & B"
// names a row by two parts apart, e.g. a bias and a map size), the cell
// of that column; STEP:facts{NAME} is a fact. Both
// sides are numbers, references, or products and quotients of them; the operators are
// ==, !=, <, <=, >, >=. Every `<!-- fact: STEP/NAME -->` placeholder of a measured step must
// name a fact of its report too.
//
// A step's README also guides the tour's report page (tools/report.py), from this run:
//   <!-- summary: TEXT -->           what the step measured and what to conclude
//   <!-- takeaway ID: TEXT -->       one line under the table ID (or "plot N": the report's
//                                    plot N, counted from 0)
//   What to look for:                a list whose bullets each carry their check comments
//   - a bullet ...                   (indented under it, or right after it): the page marks
//     <!-- check: ... -->            each bullet as agreeing with this run or not
// TEXT may hold numbers of the run: {{EXPRESSION}} (references and arithmetic, as in a
// check) or {{EXPRESSION | N}} with N decimals.
//
// usage: node slides/claims.mjs [--out DIR] [--root DIR] [--require] [--json FILE]
//   --out DIR    where the reports are (default <repo>/out)
//   --root DIR   the tree whose slides/*.md, steps/*/README.md, README.md, docs/*.md are read
//   --require    a step without a report fails instead of being skipped
//   --json FILE  also write every check's outcome and the steps' guides (summary, marked
//                bullets, takeaways with their numbers) to FILE, for the report page
//   --self-test  run the checker on tests/slides_claims/ (agreeing, contradicting and broken
//                decks against one fixture report) and fail unless it answers each rightly
// Exit 0 when every check holds, 1 when one contradicts its report or cannot be read, 77
// (ctest's skip) when no report exists at all.
import { spawnSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const args = { out: path.join(path.dirname(here), "out"), root: path.dirname(here), require: false, selfTest: false, json: null };
for (let i = 2; i < process.argv.length; ++i) {
  const k = process.argv[i];
  if (k === "--out") args.out = path.resolve(process.argv[++i]);
  else if (k === "--root") args.root = path.resolve(process.argv[++i]);
  else if (k === "--require") args.require = true;
  else if (k === "--self-test") args.selfTest = true;
  else if (k === "--json") args.json = path.resolve(process.argv[++i]);
  else {
    console.error(`slides/claims.mjs: unknown argument '${k}'`);
    process.exit(2);
  }
}

function markdownFiles(root) {
  const files = [];
  const add = (dir, filter) => {
    const d = path.join(root, dir);
    if (!fs.existsSync(d)) return;
    for (const f of fs.readdirSync(d).sort()) if (filter(f)) files.push(path.join(d, f));
  };
  add("slides", (f) => f.endsWith(".md"));
  add(".", (f) => f === "README.md");
  add("docs", (f) => f.endsWith(".md"));
  const steps = path.join(root, "steps");
  if (fs.existsSync(steps))
    for (const s of fs.readdirSync(steps).sort()) {
      const readme = path.join(steps, s, "README.md");
      if (fs.existsSync(readme)) files.push(readme);
    }
  return files;
}

const reports = new Map();
function report(step) {
  if (!reports.has(step)) {
    const file = path.join(args.out, `${step}.json`);
    let value = null;
    if (fs.existsSync(file)) {
      try {
        value = JSON.parse(fs.readFileSync(file, "utf8"));
      } catch (e) {
        value = { error: `${file} is not valid JSON (${e.message})` };
      }
    }
    reports.set(step, value);
  }
  return reports.get(step);
}

class Missing extends Error {}

// The value of one reference, or a thrown Error saying why there is none.
function resolve(step, table, row, column) {
  const r = report(step);
  if (!r) throw new Missing(`out/${step}.json does not exist (run ./workbook tour)`);
  if (r.error) throw new Error(r.error);
  if (table === "facts") {
    if (!r.facts || !(column in r.facts)) throw new Error(`out/${step}.json has no fact '${column}'`);
    return Number(r.facts[column]);
  }
  const t = (r.tables || []).find((x) => x.id === table);
  if (!t) throw new Error(`out/${step}.json has no table '${table}'`);
  const c = t.columns.indexOf(column);
  if (c < 0) throw new Error(`table ${step}:${table} has no column '${column}' (columns: ${t.columns.join(", ")})`);
  // "A & B": a row that holds both (cells apart from each other: a bias and a map size).
  const parts = (row || "").split(" & ");
  let rows = t.rows.filter((cells) => parts.every((p) => cells.map(String).join(" ").includes(p)));
  // A name inside another ("sah" in "sweep-sah", "bunny planes" in "bunny planes + corners"):
  // the one row where each part is whole cells, one cell or a run of them.
  if (rows.length > 1) {
    const whole = (cells, p) =>
      cells.some((_, i) => cells.slice(i).some((__, j) => cells.slice(i, i + j + 1).map(String).join(" ") === p));
    const exact = rows.filter((cells) => parts.every((p) => whole(cells, p)));
    if (exact.length === 1) rows = exact;
  }
  if (rows.length !== 1)
    throw new Error(`table ${step}:${table}: ${rows.length} rows contain '${row}' (need exactly one)`);
  const v = rows[0][c];
  if (typeof v !== "number") throw new Error(`${step}:${table}[${row}]{${column}} is '${v}', not a number`);
  return v;
}

const REF = /(\d\d_[A-Za-z0-9_]+):([A-Za-z0-9_]+)(?:\[([^\]]*)\])?\{([^}]*)\}/g;

// References replaced by their values: {numeric, shown}.
function substitute(expression) {
  const shown = [];
  const numeric = expression.replace(REF, (_, step, table, row, column) => {
    const v = resolve(step, table, row, column);
    shown.push(`${step}:${table}${row === undefined ? "" : `[${row}]`}{${column}} = ${v}`);
    return `(${v})`;
  });
  return { numeric, shown };
}

function arithmetic(s, expression) {
  if (!/^[0-9.eE+\-*/() ]+$/.test(s)) throw new Error(`cannot read '${s}' in '${expression}'`);
  const v = Function(`"use strict"; return (${s});`)();
  if (typeof v !== "number" || Number.isNaN(v)) throw new Error(`'${s}' in '${expression}' is not a number`);
  return v;
}

// "left OP right" with references replaced by their values; returns {ok, shown}.
export function evaluate(expression) {
  const { numeric, shown } = substitute(expression);
  const m = numeric.match(/^\s*([^<>=!]+?)\s*(==|!=|<=|>=|<|>)\s*([^<>=!]+?)\s*$/);
  if (!m) throw new Error(`cannot read '${expression}' (want: LEFT OP RIGHT)`);
  const a = arithmetic(m[1], expression), b = arithmetic(m[3], expression);
  const ok = { "==": a === b, "!=": a !== b, "<": a < b, "<=": a <= b, ">": a > b, ">=": a >= b }[m[2]];
  return { ok, shown: `${a} ${m[2]} ${b}${shown.length ? ` (${shown.join("; ")})` : ""}` };
}

// A number of the run in a sentence: 4 significant digits, integers with separators.
export function formatNumber(v, decimals) {
  if (decimals !== undefined) return v.toLocaleString("en-US", { minimumFractionDigits: decimals, maximumFractionDigits: decimals });
  if (Number.isInteger(v)) return v.toLocaleString("en-US");
  const a = Math.abs(v);
  if (a >= 1e6 || (a < 1e-3 && a > 0)) return v.toPrecision(3).replace(/\.?0+e/, "e");
  return a >= 100 ? v.toFixed(1) : String(Number(v.toPrecision(4)));
}

// TEXT with every {{EXPRESSION}} or {{EXPRESSION | N}} replaced by its number.
export function fillNumbers(text) {
  return text.replace(/\{\{((?:[^{}]|\{[^{}]*\})*)\}\}/g, (_, inside) => {
    const bar = inside.lastIndexOf("|");
    const places = bar >= 0 && /^\s*\d+\s*$/.test(inside.slice(bar + 1)) ? Number(inside.slice(bar + 1)) : undefined;
    const expression = places === undefined ? inside : inside.slice(0, bar);
    return formatNumber(arithmetic(substitute(expression).numeric.trim(), expression), places);
  });
}

// Every check and fact placeholder of one file: [{line, expression, status, shown}], status
// "agree", "disagree", "error" or "not measured".
function checkFile(file) {
  const outcomes = [];
  const lines = fs.readFileSync(file, "utf8").split(/\r?\n/);
  lines.forEach((line, i) => {
    const judge = (expression, run) => {
      try {
        outcomes.push({ line: i + 1, expression, ...run() });
      } catch (e) {
        const status = e instanceof Missing && !args.require ? "not measured" : "error";
        outcomes.push({ line: i + 1, expression, status, shown: e.message });
      }
    };
    for (const m of line.matchAll(/<!--\s*check:\s*(.*?)\s*-->/g))
      judge(m[1], () => {
        const r = evaluate(m[1]);
        return { status: r.ok ? "agree" : "disagree", shown: r.shown };
      });
    for (const fact of line.matchAll(/<!--\s*fact:?\s*(\d\d_[A-Za-z0-9_]+)\/(\S+?)(?:\s*\|\s*\d+)?\s*-->/g))
      judge(`fact: ${fact[1]}/${fact[2]}`, () => ({ status: "agree", shown: String(resolve(fact[1], "facts", undefined, fact[2])) }));
  });
  return { lines, outcomes };
}

// The guide of a step's README for the report page: its summary, its "What to look for"
// bullets with their checks' outcomes, and its takeaways, numbers filled in from the run.
// Problems (a number that cannot be read) go to `problems` as [line, message].
function guide(lines, outcomes, problems) {
  const text = lines.join("\n");
  const lineOf = (index) => text.slice(0, index).split("\n").length;
  const fill = (raw, index) => {
    const clean = raw.replace(/\s+/g, " ").trim();
    try {
      return fillNumbers(clean);
    } catch (e) {
      if (!(e instanceof Missing && !args.require)) problems.push([lineOf(index), e.message]);
      return null;
    }
  };
  const g = { summary: null, bullets: [], takeaways: {} };
  const summary = text.match(/<!--\s*summary:\s*([\s\S]*?)-->/);
  if (summary) g.summary = fill(summary[1], summary.index);
  for (const m of text.matchAll(/<!--\s*takeaway\s+([^:]+?):\s*([\s\S]*?)-->/g)) g.takeaways[m[1].trim()] = fill(m[2], m.index);
  const start = lines.findIndex((l) => /^\s*(#+\s*)?What to look for:?\s*$/.test(l));
  if (start < 0) return g;
  let bullet = null;
  for (let i = start + 1; i < lines.length; ++i) {
    const line = lines[i];
    if (/^- /.test(line)) {
      bullet = { first: i + 1, last: i + 1, text: [line.slice(2)] };
      g.bullets.push(bullet);
    } else if (bullet && (/^\s+\S/.test(line) || /^<!--\s*check:/.test(line))) {
      bullet.last = i + 1;
      bullet.text.push(line.trim());
    } else if (line.trim() !== "") break;
  }
  g.bullets = g.bullets.map((b) => {
    const checks = outcomes.filter((o) => o.line >= b.first && o.line <= b.last);
    const worst = ["error", "disagree", "not measured", "agree"].find((s) => checks.some((c) => c.status === s));
    return {
      line: b.first,
      text: b.text.join(" ").replace(/<!--[\s\S]*?-->/g, "").replace(/\s+/g, " ").trim(),
      status: worst || "unchecked",
      checks,
    };
  });
  return g;
}

function main() {
  let failed = 0, passed = 0, skipped = 0;
  const rel = (f) => path.relative(args.root, f) || f;
  const record = { out: args.out, files: {}, guides: {} };
  for (const file of markdownFiles(args.root)) {
    const { lines, outcomes } = checkFile(file);
    for (const o of outcomes) {
      const where = `${rel(file)}:${o.line}`;
      if (o.status === "agree") ++passed;
      else if (o.status === "not measured") ++skipped;
      else {
        ++failed;
        if (o.status === "disagree") console.log(`FAIL ${where}: the text states '${o.expression}', the report says ${o.shown}`);
        else if (o.expression.startsWith("fact: ")) console.log(`FAIL ${where}: the placeholder '${o.expression}': ${o.shown}`);
        else console.log(`FAIL ${where}: ${o.shown}`);
      }
    }
    record.files[rel(file)] = outcomes;
    const step = rel(file).match(/^steps\/(\d\d_[A-Za-z0-9_]+)\/README\.md$/);
    if (step) {
      const problems = [];
      record.guides[step[1]] = { readme: rel(file), ...guide(lines, outcomes, problems) };
      for (const [line, message] of problems) {
        ++failed;
        console.log(`FAIL ${rel(file)}:${line}: a number of the run in its summary or takeaway: ${message}`);
      }
    }
  }
  console.log(`stated outcomes: ${passed} agree with the reports, ${failed} do not, ${skipped} not measured${skipped ? ` (no report in ${args.out})` : ""}`);
  if (args.json) {
    record.counts = { agree: passed, fail: failed, notMeasured: skipped };
    fs.writeFileSync(args.json, JSON.stringify(record, null, 1) + "\n");
  }
  if (failed) process.exit(1);
  process.exit(passed ? 0 : 77);
}

// The checker's own test: each fixture deck must give its exit code and name its line.
function selfTest() {
  const fixtures = path.join(path.dirname(here), "tests", "slides_claims");
  const cases = [
    { root: "agree", status: 0, says: ["5 agree with the reports, 0 do not"] },
    { root: "contradict", status: 1, says: ["slides/01_fixture.md:4:", "the report says 1722 == 0"] },
    { root: "broken", status: 1, says: ["no column 'no such column'", "no fact 'no_such_fact'"] },
    { root: "agree", out: "agree", status: 77, says: ["0 agree", "not measured"] },
  ];
  let bad = 0;
  for (const c of cases) {
    const out = path.join(fixtures, c.out || "out");
    const run = spawnSync(process.execPath, [fileURLToPath(import.meta.url), "--root", path.join(fixtures, c.root), "--out", out], { encoding: "utf8" });
    const missing = c.says.filter((w) => !run.stdout.includes(w));
    const ok = run.status === c.status && !missing.length;
    if (!ok) ++bad;
    console.log(`${ok ? "ok  " : "FAIL"} ${c.root} against ${path.basename(out)}/: exit ${run.status} (want ${c.status})${missing.length ? `, output lacks '${missing.join("', '")}'` : ""}`);
    if (!ok) console.log(run.stdout + run.stderr);
  }
  process.exit(bad ? 1 : 0);
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) (args.selfTest ? selfTest : main)();
