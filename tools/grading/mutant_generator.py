"""Generated mutants: the mechanical mistakes of each exercise's solution, against its tests:
./workbook mutants --generate.

The written catalogue (tests/mutants/*.patch, mutants.py) holds the mistakes students make,
each with the test case that exists for it. This command measures the suites instead: it
makes the usual mechanical mutants of an exercise's solution body and counts how many its
tests catch (the mutation score), listing the ones that survive. Each mutant changes one
thing in one line of the body (between BEGIN SOLUTION and END SOLUTION):

  boundary     a comparison moved by one: < and <=, > and >=
  comparison   a comparison negated: < and >=, > and <=, == and !=
  arithmetic   + and -, * and /, += and -=, *= and /=, ++ and --
  logical      && and ||, a ! dropped, a unary minus dropped
  constant     an integer n as n + 1 and n - 1, a floating-point constant as 0 and twice itself
  min/max      min and max swapped (std::, glm::), floor and ceil
  statement    a statement dropped (an `if (...) return ...;` guard with it; not a body's
               last return, which would fall off the function's end)
  precision    double as float (the routine's own precision lost)

A survivor is killed by a new test case or argued equivalent (it computes what the
reference computes on every input the exercise's contract allows) in
tests/mutants/equivalent.json, one line of why each; the score leaves the equivalent ones
out. A mutant that does not compile is not counted.

usage: ./workbook mutants --generate [N.M | NN ...] [--list] [--summary | --markdown] [--timeout S] [--jobs N]
  (none: every exercise; N.M: one; NN: a step's)
  --list     the mutants, without running them
  --summary  the table of the last runs (build/mutants/generated.json), without running
  --markdown the same table in Markdown (as docs/reliability.md shows it)
  --timeout  at most these seconds for one mutant's run of the exercise's tests (default 30;
             a run may last ten times the reference's, at least 5 s)
  --jobs     compile jobs of the builds (default 2)

How: all the mutants of an exercise are compiled at once into a private copy of the tree
(mutants.py's, build/mutants/tree), each as one case of a switch over copies of the
solution body that reads the mutant's number from BOXES_MUTANT at run time (mutant
schemata: one build per exercise, not one per mutant); the exercise's doctest suite is run
once per mutant (tools/check.py's runner). The private tree is built with bounds checks
(the standard library's and GLM's asserts): a loop one past an array's end crashes there,
as CI's sanitizer run would report it. A copy that does not compile is dropped by the
compiler's line numbers and the rest built again. The file is restored afterwards.
"""
import hashlib
import json
import os
import re
import sys
import time
from dataclasses import dataclass

from . import ROOT
from .. import build as cmake
from .exercises import case_results, exercises
from .mutants import private_tree, release_tree

EQUIVALENT = "tests/mutants/equivalent.json"
RESULTS = os.path.join("build", "mutants", "generated.json")
SELECTOR = "BOXES_MUTANT"
# Copies of a body per build: a few hundred copies of a long body make one slow function.
CHUNK = 80


@dataclass
class Mutant:
    exercise: str
    number: int  # 1.. within the exercise, in line order (this run's)
    line: int  # 0-based line of the file
    operator: str
    original: str  # the original line
    mutated: list  # the line's replacement (no lines: dropped)
    key: str = ""  # stable: the exercise and a hash of the line's text and the change
    extra_line: int = -1  # a second line dropped with it (the guarded statement of an if)
    description: str = ""

    def label(self):
        return f"{self.key}: {self.description}"


# ---- Reading a line of C++ -----------------------------------------------------------------


def code_mask(line, in_block_comment=False):
    """(a string of the line's characters with comments and string or character literals
    blanked, whether a /* comment is still open at its end)."""
    out, i, n = [], 0, len(line)
    while i < n:
        if in_block_comment:
            end = line.find("*/", i)
            if end < 0:
                out.append(" " * (n - i))
                return "".join(out), True
            out.append(" " * (end + 2 - i))
            i, in_block_comment = end + 2, False
            continue
        c = line[i]
        if line.startswith("//", i):
            out.append(" " * (n - i))
            break
        if line.startswith("/*", i):
            in_block_comment = True
            out.append("  ")
            i += 2
            continue
        if c in "\"'":
            j = i + 1
            while j < n and line[j] != c:
                j += 2 if line[j] == "\\" else 1
            out.append(" " * (min(j + 1, n) - i))
            i = j + 1
            continue
        out.append(c)
        i += 1
    return "".join(out), in_block_comment


# Binary operators written with a space on each side (the repository's clang-format puts
# them so; template brackets, pointers and references have none).
BINARY = {"<": ["<=", ">="], ">": [">=", "<="], "<=": ["<", ">"], ">=": [">", "<"],
          "==": ["!="], "!=": ["=="], "+": ["-"], "-": ["+"], "*": ["/"], "/": ["*"],
          "&&": ["||"], "||": ["&&"], "+=": ["-="], "-=": ["+="], "*=": ["/="], "/=": ["*="]}
KIND = {"<": "boundary", ">": "boundary", "<=": "boundary", ">=": "boundary"}
SWAPS = [("std::min", "std::max"), ("std::max", "std::min"), ("glm::min", "glm::max"),
         ("glm::max", "glm::min"), ("std::floor", "std::ceil"), ("std::ceil", "std::floor"),
         ("std::fmin", "std::fmax"), ("std::fmax", "std::fmin")]
INTEGER = re.compile(r"(?<![\w.])(\d+)(?![\w.])")
FLOATING = re.compile(r"(?<![\w.])(\d+\.\d*(?:e[-+]?\d+)?f?|\d+e[-+]?\d+f?|0x[0-9a-fA-F.]+p[-+]?\d+f?)(?![\w.])")


def operator_kind(op, replacement):
    if op in ("<", ">", "<=", ">="):
        return "boundary" if replacement[0] == op[0] else "comparison"
    if op in ("==", "!="):
        return "comparison"
    if op in ("&&", "||"):
        return "logical"
    return "arithmetic"


def line_mutations(line, code):
    """(column, length, replacement, operator, what) for one line (code: the line with
    comments and literals blanked)."""
    found = []
    # Binary and compound operators with spaces around them.
    for m in re.finditer(r"(?<= )(<=|>=|==|!=|&&|\|\||\+=|-=|\*=|/=|<|>|\+|-|\*|/)(?= )", code):
        op = m.group(1)
        for rep in BINARY[op]:
            found.append((m.start(), len(op), rep, operator_kind(op, rep), f"`{op}` as `{rep}`"))
    # ++ and --.
    for m in re.finditer(r"\+\+|--", code):
        rep = "--" if m.group(0) == "++" else "++"
        found.append((m.start(), 2, rep, "arithmetic", f"`{m.group(0)}` as `{rep}`"))
    # A logical not dropped: !( or !name.
    for m in re.finditer(r"!(?=[(\w])", code):
        found.append((m.start(), 1, "", "logical", "a `!` dropped"))
    # A unary minus dropped: after an opening bracket, a comma, = or return.
    for m in re.finditer(r"(?:(?<=[(,=?:])|(?<=[(,=?:] )|(?<=return ))-(?=[\w(])", code):
        found.append((m.start(), 1, "", "logical", "a unary minus dropped"))
    # min and max, floor and ceil.
    for a, b in SWAPS:
        for m in re.finditer(re.escape(a) + r"\b", code):
            found.append((m.start(), len(a), b, "min/max", f"`{a}` as `{b}`"))
    # Constants.
    for m in FLOATING.finditer(code):
        text = m.group(1)
        suffix = "f" if text.endswith("f") and not text.startswith("0x") else ""
        try:
            value = float.fromhex(text.rstrip("f")) if text.startswith("0x") else float(text.rstrip("f"))
        except ValueError:
            continue
        for rep in ([0.0, 2 * value] if value != 0 else [1.0]):
            r = repr(rep) + suffix
            found.append((m.start(), len(text), r, "constant", f"`{text}` as `{r}`"))
    masked = FLOATING.sub(lambda m: " " * len(m.group(0)), code)
    for m in INTEGER.finditer(masked):
        value = int(m.group(1))
        for rep in (value + 1, value - 1):
            if rep < 0:
                continue
            found.append((m.start(), len(m.group(1)), str(rep), "constant", f"`{value}` as `{rep}`"))
    # Double as float; in a template, a variable of the routine's own type T as float.
    for m in re.finditer(r"\bdouble\b", code):
        found.append((m.start(), 6, "float", "precision", "`double` as `float`"))
    for m in re.finditer(r"(?<![\w:<])T(?= [A-Za-z_]\w*(?: =|,|;| \{))", code):
        found.append((m.start(), 1, "float", "precision", "a `T` variable as `float`"))
    for m in re.finditer(r"Vec3T<T>(?= [A-Za-z_]\w*(?: =|,|;| \{|\())", code):
        found.append((m.start(), len(m.group(0)), "Vec3T<float>", "precision", "a `Vec3T<T>` as `Vec3T<float>`"))
    return found


def statement_drops(lines, codes):
    """(line, extra line or -1, what) for each statement a mutant may drop: a line that is
    one whole statement, or an unbraced `if (...)`/`for (...)` with its statement."""
    drops = []
    for i, code in enumerate(codes):
        text = code.strip()
        if not text.endswith(";") or text.startswith(("}", "case ", "default")):
            continue
        if text.count("(") != text.count(")") or text.count("{") != text.count("}"):
            continue
        if text.startswith("return "):
            continue  # a body without its last return falls off its end: undefined, not a mistake
        prev = codes[i - 1].strip() if i > 0 else ""
        if re.match(r"(if|for|while)\b", prev) and prev.endswith(")") and prev.count("(") == prev.count(")"):
            drops.append((i - 1, i, "`" + prev + " " + text + "` dropped"))
            continue
        if prev.endswith((",", "(", "=", "&&", "||", "+", "-", "*", "/", "?", ":")):
            continue  # the end of a statement that started above
        drops.append((i, -1, "dropped"))
    return drops


def generate(path, ex):
    """The mutants of one exercise's solution body in `path` (the tree's file)."""
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    body = list(range(ex.begin + 1, ex.end))
    codes, open_comment = [], False
    for i in body:
        code, open_comment = code_mask(lines[i], open_comment)
        codes.append(code)
    mutants, seen = [], {}

    def add(line, operator, mutated, description, extra=-1, salt=""):
        stripped = lines[line].strip()
        digest = hashlib.sha1("\0".join([ex.id, stripped, operator, description, salt,
                                         lines[extra].strip() if extra >= 0 else ""]).encode()).hexdigest()[:8]
        key = f"{ex.id}-{digest}"
        seen[key] = seen.get(key, 0) + 1
        if seen[key] > 1:  # the same line twice in a body: the second keeps its own key
            key += f"-{seen[key]}"
        where = f"line {line + 1}: "
        text = (f"`{stripped}` dropped" if description == "dropped"
                else description if operator == "statement" else f"{description} in `{stripped}`")
        mutants.append(Mutant(ex.id, 0, line, operator, lines[line], mutated, key, extra, where + text))

    for k, i in enumerate(body):
        line, code = lines[i], codes[k]
        for col, length, rep, operator, what in line_mutations(line, code):
            add(i, operator, [line[:col] + rep + line[col + length:]], what,
                salt=str(len(code[:col].split())))
    for i, extra, what in statement_drops([lines[j] for j in body], codes):
        add(body[i], "statement", [], what, extra=body[extra] if extra >= 0 else -1)
    mutants.sort(key=lambda m: (m.line, m.operator, m.description))
    for n, m in enumerate(mutants, 1):
        m.number = n
    return mutants


# ---- The schema -----------------------------------------------------------------------------------

SELECTOR_FUNCTION = [
    "#include <cstdlib>",
    "namespace {",
    "// Added by tools/grading/mutant_generator.py (the private tree only): which mutant runs.",
    "[[maybe_unused]] int boxesGeneratedMutant() {",
    f"    static const int id = [] {{ const char* s = std::getenv(\"{SELECTOR}\"); return s ? std::atoi(s) : 0; }}();",
    "    return id;",
    "}",
    "}  // namespace",
]


def schema(text, ex, mutants):
    """The file's text with the exercise's body replaced by a switch over the mutants'
    bodies; returns (text, {mutant number: (first line, last line)} 1-based)."""
    lines = text.split("\n")
    at = max(i for i, l in enumerate(lines[: ex.begin]) if l.startswith("#include")) + 1
    body = lines[ex.begin + 1 : ex.end]
    out = lines[:at] + SELECTOR_FUNCTION + lines[at : ex.begin + 1]
    out.append("switch (boxesGeneratedMutant()) {")
    ranges = {}
    for m in mutants:
        copy = []
        for j, l in enumerate(body):
            i = ex.begin + 1 + j
            if i == m.line:
                copy += m.mutated
            elif i == m.extra_line:
                continue
            else:
                copy.append(l)
        out.append(f"case {m.number}: {{")
        first = len(out) + 1
        out += copy
        ranges[m.number] = (first - 1, len(out) + 1)
        out.append("} break;")
    out.append("default: {")
    out += body
    out.append("} break;")
    out.append("}")
    out += lines[ex.end:]
    return "\n".join(out), ranges


def error_lines(output, rel):
    """The lines of `rel` that the compiler's errors name (a set; empty: none)."""
    found = set()
    name = re.escape(rel)
    for m in re.finditer(r"^(?:.*/)?" + name + r":(\d+):(?:\d+:)? (?:fatal )?error:", output, re.M):
        found.add(int(m.group(1)))
    return found


# ---- Running --------------------------------------------------------------------------------------


# The mutants' build checks bounds: the standard library's (std::array, std::vector) and
# GLM's (its asserts, which the release flags' NDEBUG turns off: glm::vec3's operator[]
# then reads x for index 3), and a plain array's (-fsanitize=bounds, stopping at the first
# error). A loop one past its end is a crash the tests see, as CI's sanitizer run sees it,
# instead of a read the release build may survive. A local variable read before it is
# written holds a pattern (-ftrivial-auto-var-init=pattern: NaN for a float), not whatever the
# stack held, which may be the right value. -O2: the same arithmetic as -O3 (no fast math,
# no contraction) at less compile time.
CHECKED = {"CMAKE_CXX_FLAGS": "-D_GLIBCXX_ASSERTIONS -fsanitize=bounds -fno-sanitize-recover=bounds"
                              " -ftrivial-auto-var-init=pattern",
           "CMAKE_CXX_FLAGS_RELEASE": "-O2"}

def build_tree(tree):
    """The private tree's build: mutants.py's (no step programs, no link-time optimisation)
    with CHECKED, in a folder of its own (build/generated): the written catalogue's build
    keeps its flags, so running one after the other rebuilds nothing. No test discovery:
    the suites are run here, not by ctest, and discovery would run the program after each
    link."""
    t = release_tree(tree)
    t.build = os.path.join(tree, "build", "generated")
    t.cache.update(CHECKED)
    t.cache["BOXES_TESTS_DISCOVER"] = "OFF"
    return t


def build(btree, step, log, jobs):
    """Builds the step's test program: (ok, the compiler's output)."""
    r = cmake.build(btree, [f"test_step{step:02d}"], jobs=jobs, log=log)
    log.flush()
    return r.ok, r.output


def run_tests(btree, step, exercise, number, timeout):
    """(killed, how): the exercise's suite with mutant `number` selected."""
    from ..check import run_suite  # noqa: PLC0415 (the student loop's runner)

    binary = os.path.join(btree.build, "tests", f"test_step{step:02d}")
    os.environ[SELECTOR] = str(number)
    try:
        kind, data, detail = run_suite(binary, exercise, timeout)
    finally:
        os.environ.pop(SELECTOR, None)
    if kind != "ok":
        return True, f"{kind} {detail}".strip()
    results = case_results(data)
    if not results:
        return True, "no test results"
    failing = [r.name for r in results if not r.passed]
    return bool(failing), "; ".join(failing)


def load_equivalent(root=ROOT):
    try:
        with open(os.path.join(root, EQUIVALENT), encoding="utf-8") as f:
            data = json.load(f)
        return data if isinstance(data, dict) else {}
    except (OSError, ValueError):
        return {}


def load_results(root=ROOT):
    try:
        with open(os.path.join(root, RESULTS), encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def save_results(results, root=ROOT):
    path = os.path.join(root, RESULTS)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path + ".new", "w", encoding="utf-8") as f:
        json.dump(results, f, indent=1, sort_keys=True)
    os.replace(path + ".new", path)


def run_exercise(tree, btree, ex, mutants, timeout, log, say, jobs=2):
    """Every mutant of one exercise: {key: (status, how)}, status killed, survived,
    stillborn (does not compile) or reference (the reference itself fails). A mutant's run
    may last ten times the reference's (at least 5 s, at most `timeout`): a mutant that
    loops costs seconds, not the whole timeout."""
    rel = ex.path
    path = os.path.join(tree, rel)
    with open(path, encoding="utf-8") as f:
        original = f.read()
    outcome = {}
    try:
        for start in range(0, len(mutants), CHUNK):
            chunk = mutants[start : start + CHUNK]
            while True:
                text, ranges = schema(original, ex, chunk)
                with open(path, "w", encoding="utf-8") as f:
                    f.write(text)
                say(f"[generated] {ex.id}: building {len(chunk)} mutants (one switch)")
                ok, output = build(btree, ex.step, log, jobs)
                if ok:
                    break
                bad = set()
                lines = error_lines(output, rel)
                for line in lines:
                    bad |= {n for n, (a, b) in ranges.items() if a <= line <= b}
                if len(bad) > max(3, len(chunk) // 2):
                    # Errors that cascade past one copy (a brace lost): drop the first one only.
                    bad = {n for n, (a, b) in ranges.items() if a <= min(lines) <= b}
                if not bad:
                    raise RuntimeError(f"{ex.id}: the schema does not compile outside the mutants' "
                                       f"copies (see {log.name})")
                for m in chunk:
                    if m.number in bad:
                        outcome[m.key] = ("stillborn", "does not compile")
                chunk = [m for m in chunk if m.number not in bad]
                if not chunk:
                    break
            if not chunk:
                continue
            t0 = time.monotonic()
            killed, how = run_tests(btree, ex.step, ex.id, 0, timeout)
            limit = min(timeout, max(5.0, 10 * (time.monotonic() - t0)))
            if killed:
                for m in chunk:
                    outcome[m.key] = ("reference", how)
                say(f"[generated] {ex.id}: the reference fails its own tests ({how}); skipped")
                continue
            for m in chunk:
                killed, how = run_tests(btree, ex.step, ex.id, m.number, limit)
                outcome[m.key] = ("killed" if killed else "survived", how)
    finally:
        with open(path, "w", encoding="utf-8") as f:
            f.write(original)
        os.utime(path)
    return outcome


def select(all_ex, words):
    if not words:
        return all_ex
    chosen = []
    for w in words:
        found = [e for e in all_ex if e.id == w or (re.fullmatch(r"\d\d?", w) and e.step == int(w))]
        if not found:
            raise SystemExit(f"mutants --generate: no exercise or step '{w}'")
        chosen += [e for e in found if e not in chosen]
    return chosen


def score_row(ex_id, entry, equivalent):
    """(generated, stillborn, killed, equivalent, survivors, score %) from one exercise's
    stored outcome."""
    outcome = entry.get("outcome", {})
    stillborn = sum(1 for s, _ in outcome.values() if s == "stillborn")
    killed = sum(1 for s, _ in outcome.values() if s == "killed")
    survivors = [k for k, (s, _) in outcome.items() if s == "survived"]
    eq = [k for k in survivors if k in equivalent]
    left = [k for k in survivors if k not in equivalent]
    counted = killed + len(left)
    score = 100.0 * killed / counted if counted else None  # nothing to score
    return len(outcome), stillborn, killed, len(eq), left, score


def score_text(n, score):
    """The score column: a percentage, or why there is none."""
    if score is not None:
        return f"{score:.1f}%"
    return "no mutants" if n == 0 else "none counted"


def print_summary(results, equivalent, chosen=None, descriptions=None, markdown=False):
    rows = []
    for ex_id in sorted(results, key=lambda s: tuple(int(x) for x in s.split("."))):
        if chosen and ex_id not in chosen:
            continue
        rows.append((ex_id,) + score_row(ex_id, results[ex_id], equivalent))
    if markdown:
        return print_markdown(rows)
    print(f"{'exercise':<9} {'mutants':>7} {'no build':>8} {'killed':>6} {'equivalent':>10} "
          f"{'survived':>8} {'score':>7}")
    for ex_id, n, still, killed, eq, left, score in rows:
        print(f"{ex_id:<9} {n:>7} {still:>8} {killed:>6} {eq:>10} {len(left):>8} "
              f"{score_text(n, score):>7}")
    if rows:
        n, still, killed, eq, left, score = totals(rows)
        print(f"{'all':<9} {n:>7} {still:>8} {killed:>6} {eq:>10} {left:>8} "
              f"{score_text(n, score):>7}")
    survivors = [(r[0], k) for r in rows for k in r[5]]
    if survivors:
        print("\nsurvivors (kill them with a test case, or argue them equivalent in "
              f"{EQUIVALENT}):")
        for ex_id, k in survivors:
            d = (descriptions or {}).get(k) or results[ex_id].get("descriptions", {}).get(k, "")
            print(f"  {k}: {d}")
    return 1 if any(too_low(r) for r in rows) else 0


def totals(rows):
    """The "all" row: the columns summed, the score over every killed and surviving mutant."""
    killed = sum(r[3] for r in rows)
    left = sum(len(r[5]) for r in rows)
    score = 100.0 * killed / (killed + left) if killed + left else None
    return (sum(r[1] for r in rows), sum(r[2] for r in rows), killed, sum(r[4] for r in rows),
            left, score)


def too_low(row):
    """Below the 95% every exercise's suite must reach (an exercise without mutants has no score)."""
    return row[6] is not None and row[6] < 95.0


def print_markdown(rows):
    """The table of print_summary as Markdown (docs/reliability.md shows it)."""
    print("| exercise | generated | stillborn | killed | equivalent | survived | score |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for ex_id, n, still, killed, eq, left, score in rows:
        print(f"| {ex_id} | {n} | {still} | {killed} | {eq} | {len(left)} | {score_text(n, score)} |")
    n, still, killed, eq, left, score = totals(rows)
    print(f"| all | {n} | {still} | {killed} | {eq} | {left} | {score_text(n, score)} |")
    return 1 if any(too_low(r) for r in rows) else 0


def main(argv):
    args = [a for a in argv if not a.startswith("-")]
    flags = [a for a in argv if a.startswith("-") and a != "--generate"]
    timeout, jobs = 30.0, 2
    for name in ("--timeout", "--jobs"):
        if name not in flags:
            continue
        i = argv.index(name)
        try:
            value = float(argv[i + 1]) if name == "--timeout" else int(argv[i + 1])
        except (IndexError, ValueError):
            print(f"mutants --generate: {name} needs a number", file=sys.stderr)
            return 2
        if value <= 0:
            print(f"mutants --generate: {name} needs a positive number", file=sys.stderr)
            return 2
        timeout, jobs = (value, jobs) if name == "--timeout" else (timeout, value)
        args = [a for a in args if a != argv[i + 1]]
        flags.remove(name)
    for f in flags:
        if f not in ("--list", "--summary", "--markdown", "-h", "--help"):
            print(f"mutants --generate: unknown option '{f}'", file=sys.stderr)
            return 2
    if "-h" in flags or "--help" in flags:
        print(__doc__.split("usage:", 1)[1].split("\n\n")[0].strip())
        return 0
    all_ex = [e for e in exercises(ROOT) if e.begin >= 0 and e.end >= 0]
    chosen = select(all_ex, args)
    equivalent = load_equivalent()
    if "--summary" in flags or "--markdown" in flags:
        return print_summary(load_results(), equivalent, {e.id for e in chosen} if args else None,
                             markdown="--markdown" in flags)
    generated = {e.id: generate(os.path.join(ROOT, e.path), e) for e in chosen}
    if "--list" in flags:
        for e in chosen:
            for m in generated[e.id]:
                mark = "  (equivalent)" if m.key in equivalent else ""
                print(f"{m.label()}  [{m.operator}]{mark}")
        print(f"{sum(len(v) for v in generated.values())} mutants of {len(chosen)} exercises",
              file=sys.stderr)
        return 0
    if not os.path.isfile(os.path.join(ROOT, "tools", "grading", "grade.py")):
        print("mutants --generate: runs in the reference tree (with the solutions), not in a starter kit",
              file=sys.stderr)
        return 2
    # The private tree's build through the compiler cache where there is one (until the CMake
    # files use it themselves), at low priority: it is long, and the machine is shared.
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        cache_in_cmake = "BOXES_CCACHE" in f.read()
    if not cache_in_cmake and not os.environ.get("CMAKE_CXX_COMPILER_LAUNCHER") and os.path.exists("/usr/bin/ccache"):
        os.environ["CMAKE_CXX_COMPILER_LAUNCHER"] = "ccache"
    os.nice(10)
    tree = private_tree()
    btree = build_tree(tree)
    log_path = os.path.join(ROOT, "build", "mutants", "generated-log.txt")
    results = load_results()
    started = time.monotonic()

    def say(text):
        print(text, file=sys.stderr, flush=True)

    with open(log_path, "w", encoding="utf-8") as log:
        if not cmake.configure(btree, log=log).ok:
            print(f"mutants --generate: configuring the private tree failed (see {log_path})", file=sys.stderr)
            return 1
        for e in chosen:
            t0 = time.monotonic()
            mutants = generated[e.id]
            outcome = run_exercise(tree, btree, e, mutants, timeout, log, say, jobs)
            results[e.id] = {
                "outcome": outcome,
                "descriptions": {m.key: m.description for m in mutants},
                "operators": {m.key: m.operator for m in mutants},
                "seconds": round(time.monotonic() - t0, 1),
            }
            save_results(results)
            n, still, killed, eq, left, score = score_row(e.id, results[e.id], equivalent)
            say(f"[generated] {e.id}: {killed} of {killed + len(left)} killed ({score_text(n, score)}), "
                f"{eq} equivalent, {still} do not compile, in {results[e.id]['seconds']:.0f} s")
    status = print_summary(results, equivalent, {e.id for e in chosen})
    print(f"\n{len(chosen)} exercises in {time.monotonic() - started:.0f} s "
          f"(log: {os.path.relpath(log_path, ROOT)}; results: {RESULTS})")
    return status


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
