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
// usage: node slides/claims.mjs [--out DIR] [--root DIR] [--require]
//   --out DIR    where the reports are (default <repo>/out)
//   --root DIR   the tree whose slides/*.md, steps/*/README.md, README.md, docs/*.md are read
//   --require    a step without a report fails instead of being skipped
//   --self-test  run the checker on tests/slides_claims/ (agreeing, contradicting and broken
//                decks against one fixture report) and fail unless it answers each rightly
// Exit 0 when every check holds, 1 when one contradicts its report or cannot be read, 77
// (ctest's skip) when no report exists at all.
import { spawnSync } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { fileURLToPath } from "node:url";

const here = path.dirname(fileURLToPath(import.meta.url));
const args = { out: path.join(path.dirname(here), "out"), root: path.dirname(here), require: false, selfTest: false };
for (let i = 2; i < process.argv.length; ++i) {
  const k = process.argv[i];
  if (k === "--out") args.out = path.resolve(process.argv[++i]);
  else if (k === "--root") args.root = path.resolve(process.argv[++i]);
  else if (k === "--require") args.require = true;
  else if (k === "--self-test") args.selfTest = true;
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

// "left OP right" with references replaced by their values; returns {ok, shown}.
export function evaluate(expression) {
  const shown = [];
  const numeric = expression.replace(REF, (_, step, table, row, column) => {
    const v = resolve(step, table, row, column);
    shown.push(`${step}:${table}${row === undefined ? "" : `[${row}]`}{${column}} = ${v}`);
    return `(${v})`;
  });
  const m = numeric.match(/^\s*([^<>=!]+?)\s*(==|!=|<=|>=|<|>)\s*([^<>=!]+?)\s*$/);
  if (!m) throw new Error(`cannot read '${expression}' (want: LEFT OP RIGHT)`);
  const arithmetic = (s) => {
    if (!/^[0-9.eE+\-*/() ]+$/.test(s)) throw new Error(`cannot read '${s}' in '${expression}'`);
    const v = Function(`"use strict"; return (${s});`)();
    if (typeof v !== "number" || Number.isNaN(v)) throw new Error(`'${s}' in '${expression}' is not a number`);
    return v;
  };
  const a = arithmetic(m[1]), b = arithmetic(m[3]);
  const ok = { "==": a === b, "!=": a !== b, "<": a < b, "<=": a <= b, ">": a > b, ">=": a >= b }[m[2]];
  return { ok, shown: `${a} ${m[2]} ${b}${shown.length ? ` (${shown.join("; ")})` : ""}` };
}

function main() {
  let failed = 0, passed = 0, skipped = 0;
  const rel = (f) => path.relative(args.root, f) || f;
  for (const file of markdownFiles(args.root)) {
    const lines = fs.readFileSync(file, "utf8").split(/\r?\n/);
    lines.forEach((line, i) => {
      const where = `${rel(file)}:${i + 1}`;
      for (const m of line.matchAll(/<!--\s*check:\s*(.*?)\s*-->/g)) {
        try {
          const r = evaluate(m[1]);
          if (r.ok) ++passed;
          else {
            ++failed;
            console.log(`FAIL ${where}: the text states '${m[1]}', the report says ${r.shown}`);
          }
        } catch (e) {
          if (e instanceof Missing && !args.require) {
            ++skipped;
            continue;
          }
          ++failed;
          console.log(`FAIL ${where}: ${e.message}`);
        }
      }
      for (const fact of line.matchAll(/<!--\s*fact:?\s*(\d\d_[A-Za-z0-9_]+)\/(\S+?)\s*-->/g)) {
        try {
          resolve(fact[1], "facts", undefined, fact[2]);
          ++passed;
        } catch (e) {
          if (e instanceof Missing && !args.require) ++skipped;
          else {
            ++failed;
            console.log(`FAIL ${where}: the placeholder 'fact: ${fact[1]}/${fact[2]}': ${e.message}`);
          }
        }
      }
    });
  }
  console.log(`stated outcomes: ${passed} agree with the reports, ${failed} do not, ${skipped} not measured${skipped ? ` (no report in ${args.out})` : ""}`);
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
