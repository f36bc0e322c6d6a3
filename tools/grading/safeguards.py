"""The safeguards of the named hard cases, each removed, against the tests:
./workbook mutants --safeguards.

A hard case (a triangle 1e21 across, a sphere 1e5 away, a hit exactly at t == tmin) is
only proven when its test fails without the safeguard it protects. Each safeguard's
removal is a small patch against the reference in tests/safeguards/, named
short-name.patch, with header lines before the diff:

    Safeguard: the renderer's origin offset grows with the coordinates
    Caught by: hard case: no self-intersection acne on spheres at scene scales 1 to 1e5

One "Caught by:" line per test case that must fail (a core safeguard may protect cases
in more than one test program); a case name that two test programs share is written with
its program, "Caught by: test_step01: hard case: ...". The patch is applied to the private tree of the students'
mistakes (tools/grading/mutants.py), the programs holding the named cases are built, and
in those programs every hard case (the cases named "hard case: ...") and the named cases
run. The safeguard is proven when exactly the named cases fail: not one of them passes,
and no other hard case of those programs fails with it (a patch that breaks everything
proves nothing about one case). The reference's run of the same cases must pass first.

usage: ./workbook mutants --safeguards [NAME ...] [--list] [--check]
  (none: every safeguard; NAME: those, in the order given)
  --list   the catalogue
  --check  only check the catalogue: every patch applies and names cases that exist
"""
import glob
import os
import re
import subprocess
import sys
import time
from dataclasses import dataclass, field

from . import ROOT
from .. import build
from .mutants import TEST_TIMEOUT, applied_marker, build_dir, configure, git_apply
from .mutants import list_or_check, private_tree, release_tree

SAFEGUARDS_DIR = "tests/safeguards"
NAME = re.compile(r"^[a-z0-9][a-z0-9-]*\.patch$")
CASE = re.compile(r"TEST_CASE\s*\(((?:\s*\"(?:[^\"\\]|\\.)*\")+)")


@dataclass
class Safeguard:
    id: str  # "offset-scales"
    path: str  # absolute
    safeguard: str = ""
    caught_by: list = field(default_factory=list)


def read_safeguard(path):
    name = os.path.basename(path)
    if not NAME.match(name):
        raise ValueError(f"{name}: a safeguard is named short-name.patch")
    s = Safeguard(name[: -len(".patch")], path)
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("diff --git") or line.startswith("--- "):
                break
            if line.startswith("Safeguard:"):
                s.safeguard = line.split(":", 1)[1].strip()
            elif line.startswith("Caught by:"):
                s.caught_by.append(line.split(":", 1)[1].strip())
    return s


def catalogue(root=ROOT):
    paths = glob.glob(os.path.join(root, SAFEGUARDS_DIR, "*.patch"))
    return sorted((read_safeguard(p) for p in paths), key=lambda s: s.id)


def program_of_source(name):
    """The test program a tests/*.cpp file is built into (tests/CMakeLists.txt):
    stepNN_*.cpp into test_stepNN, core.cpp and hard_cases.cpp into test_core, NAME.cpp
    into test_NAME."""
    base = name[: -len(".cpp")]
    m = re.match(r"^step(\d\d)_", base)
    if m:
        return f"test_step{m.group(1)}"
    if base in ("core", "hard_cases"):
        return "test_core"
    return f"test_{base}"


def case_programs(root=ROOT):
    """{test case name: the test programs that have it} over tests/*.cpp."""
    found = {}
    for path in sorted(glob.glob(os.path.join(root, "tests", "*.cpp"))):
        with open(path, encoding="utf-8") as f:
            text = f.read()
        for m in CASE.finditer(text):
            name = "".join(re.findall(r"\"((?:[^\"\\]|\\.)*)\"", m.group(1)))
            found.setdefault(name, set()).add(program_of_source(os.path.basename(path)))
    return found


def named_cases(s, where):
    """The safeguard's cases as (program, case) pairs, or a problem (a string) for a name
    that no program or more than one program has."""
    pairs = []
    for entry in s.caught_by:
        program, _, case = entry.partition(": ")
        if program.startswith("test_") and case in where:
            if program not in where[case]:
                return f"{s.id}: {program} has no test case named '{case}'"
            pairs.append((program, case))
        elif entry not in where:
            return f"{s.id}: no test case named '{entry}'"
        elif len(where[entry]) > 1:
            return (f"{s.id}: '{entry}' is a test case of {', '.join(sorted(where[entry]))}: "
                    f"name its program ('Caught by: PROGRAM: case')")
        else:
            pairs.append((next(iter(where[entry])), entry))
    return pairs


def check_catalogue(root=ROOT, tree=None):
    """Problems with the catalogue (empty when sound): each patch has its Safeguard line,
    names at least one test case, every named case exists, and the patch applies."""
    problems = []
    safeguards = catalogue(root)
    if not safeguards:
        problems.append(f"{SAFEGUARDS_DIR}: no safeguards")
    where = case_programs(root)
    for s in safeguards:
        if not s.safeguard:
            problems.append(f"{s.id}: no 'Safeguard:' line")
        if not s.caught_by:
            problems.append(f"{s.id}: no 'Caught by:' line")
        pairs = named_cases(s, where)
        if isinstance(pairs, str):
            problems.append(pairs)
        r = git_apply(tree or root, s.path, "--check")
        if r.returncode != 0:
            first = r.stderr.strip().splitlines()[0] if r.stderr.strip() else ""
            problems.append(f"{s.id}: does not apply: {first}")
    return problems


def is_hard_case(name):
    return name.startswith("hard case")


def listed_tests(tree):
    """{ctest name: ctest number} of the private tree's build ("test_core: hard case: ...")."""
    r = subprocess.run(["ctest", "--test-dir", build_dir(tree), "-N"], capture_output=True,
                       text=True)
    # ctest -N shows the name without the blank after the program's prefix.
    return {f"{m.group(2)}: {m.group(3)}": int(m.group(1))
            for m in re.finditer(r"^\s*Test\s+#(\d+): (test_\w+): ?(.*?)\s*$", r.stdout, re.M)}


def ctest_name(pair):
    return f"{pair[0]}: {pair[1]}"


def chosen_tests(listed, named):
    """The ctest tests to run: every hard case of the named cases' programs and the named
    cases ((program, case) pairs)."""
    programs = {p for p, _ in named}
    wanted = {ctest_name(n) for n in named}
    chosen = {}
    for test, number in listed.items():
        program, _, case = test.partition(": ")
        if program in programs and (is_hard_case(case) or test in wanted):
            chosen[test] = number
    return chosen


def build_and_run(tree, named, log, title):
    """Builds the named cases' programs, runs their hard cases and the named cases: (status,
    failing tests as "program: case"), the status "passed", "failed", "no build" or "no
    tests"."""
    programs = {p for p, _ in named}
    log.write(f"\n==== {title}: build {' '.join(sorted(programs))}\n")
    log.flush()
    if not build.build(release_tree(tree), sorted(programs), jobs=2, log=log).ok:
        return "no build", []
    chosen = chosen_tests(listed_tests(tree), named)
    missing = [ctest_name(n) for n in named if ctest_name(n) not in chosen]
    if not chosen or missing:
        return "no tests", missing
    numbers = ",".join(str(n) for n in sorted(chosen.values()))
    t = subprocess.run(["ctest", "--test-dir", build_dir(tree), "-I", f"0,0,0,{numbers}",
                        "--timeout", str(TEST_TIMEOUT), "--output-on-failure"],
                       capture_output=True, text=True)
    out = t.stdout if len(t.stdout) < 200000 else t.stdout[:100000] + "\n[...]\n" + t.stdout[-100000:]
    log.write(out + t.stderr)
    failing = re.findall(r"^\s*\d+ - (test_\w+): ?(.*?) \((?:Failed|Timeout|SEGFAULT|"
                         r"Subprocess aborted|Exception|Child aborted|ILLEGAL|BUS|NUMERICAL|"
                         r"OTHER_FAULT)\)", t.stdout, re.M)
    failing = [f"{program}: {case}" for program, case in failing]
    ran = len(re.findall(r"^\s*\d+/\d+ Test\s+#\d+:", t.stdout, re.M))
    if ran != len(chosen):
        return "no tests", [f"{ran} of {len(chosen)} tests ran"]
    return ("passed" if t.returncode == 0 else "failed"), failing


def verdict(named, status, failing):
    """'proven' when exactly the named cases ((program, case) pairs) fail."""
    if status == "passed":
        return "MISSED"
    if status != "failed":
        return status
    wanted = {ctest_name(n) for n in named}
    if set(failing) == wanted:
        return "proven"
    if not wanted <= set(failing):
        return "named case passes"
    return "other hard cases fail too"


def run_one(tree, s, named, log):
    with open(applied_marker(tree), "w", encoding="utf-8") as f:
        f.write(s.path)
    r = git_apply(tree, s.path)
    if r.returncode != 0:
        os.remove(applied_marker(tree))
        return "no apply", [r.stderr.strip()]
    try:
        status, failing = build_and_run(tree, named, log, s.id)
        return verdict(named, status, failing), failing
    finally:
        r = git_apply(tree, s.path, "-R")
        if r.returncode != 0:
            raise SystemExit(f"safeguards: could not revert {s.id}: {r.stderr.strip()}")
        os.remove(applied_marker(tree))


def table(rows):
    """rows: (safeguard, result, failing cases) -> text."""
    head = ("safeguard removed", "result", "failing test cases")
    lines = [head] + [(s, r, "; ".join(c) if c else "-") for s, r, c in rows]
    w = [max(len(r[i]) for r in lines) for i in range(2)]
    return "\n".join(f"{r[0]:<{w[0]}}  {r[1]:<{w[1]}}  {r[2]}" for r in lines)


def main(argv):
    args = [a for a in argv if not a.startswith("-")]
    flags = [a for a in argv if a.startswith("-") and a != "--safeguards"]
    for f in flags:
        if f not in ("--list", "--check", "-h", "--help"):
            print(f"safeguards: unknown option '{f}'", file=sys.stderr)
            return 2
    if "-h" in flags or "--help" in flags:
        print(__doc__.split("usage:", 1)[1].split("\n\n")[0].strip())
        return 0
    safeguards = catalogue()
    if args:
        by_id = {s.id: s for s in safeguards}
        unknown = [a for a in args if a not in by_id]
        if unknown:
            print(f"safeguards: no safeguard '{unknown[0]}' (--safeguards --list)", file=sys.stderr)
            return 2
        safeguards = [by_id[a] for a in args]
    status, _ = list_or_check("safeguards", "safeguards", safeguards, len(catalogue()),
                              lambda s: f"{s.id:<32} {s.safeguard}", check_catalogue, flags,
                              stop_on_problems=True)
    if status is not None:
        return status
    where = case_programs()
    tree = private_tree()
    log_path = os.path.join(ROOT, "build", "mutants", "safeguards-log.txt")
    rows, started, checked = [], time.monotonic(), {}
    with open(log_path, "w", encoding="utf-8") as log:
        if not configure(tree, log):
            print(f"safeguards: configuring the private tree failed (see {log_path})",
                  file=sys.stderr)
            return 1
        named = {s.id: named_cases(s, where) for s in safeguards}
        for i, s in enumerate(safeguards):
            key = tuple(sorted({p for p, _ in named[s.id]}))
            if key not in checked:
                print(f"[safeguards] the reference's hard cases in {' '.join(key)}",
                      file=sys.stderr, flush=True)
                same = sorted({n for x in safeguards for n in named[x.id]
                               if tuple(sorted({p for p, _ in named[x.id]})) == key})
                checked[key] = build_and_run(tree, same, log, "reference")
                if checked[key][0] != "passed":
                    print(f"safeguards: the reference fails in {' '.join(key)} "
                          f"({checked[key][0]}: {'; '.join(checked[key][1]) or 'see the log'})",
                          file=sys.stderr, flush=True)
            if checked[key][0] != "passed":
                rows.append((s.id, "reference fails", checked[key][1]))
                continue
            print(f"[safeguards] {i + 1}/{len(safeguards)} {s.id}", file=sys.stderr, flush=True)
            result, failing = run_one(tree, s, named[s.id], log)
            rows.append((s.id, result, failing))
            print(f"[safeguards] {s.id}: {result} ({'; '.join(failing) or '-'})",
                  file=sys.stderr, flush=True)
    print(table(rows))
    bad = [r for r in rows if r[1] != "proven"]
    print(f"\n{len(rows) - len(bad)} of {len(rows)} safeguards proven (exactly their named cases "
          f"fail without them) in {time.monotonic() - started:.0f} s "
          f"(log: {os.path.relpath(log_path, ROOT)})")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
