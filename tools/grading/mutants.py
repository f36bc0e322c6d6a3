"""The mistakes students make, tried against the exercises' tests: ./workbook mutants.

Each mistake is a small patch against the reference solution in tests/mutants/, named
N.M-short-name.patch (N.M the exercise), with two header lines before the diff:

    Mistake: Moller-Trumbore without the v >= 0 rejection
    Caught by: Moller-Trumbore: a point past the second edge (v < 0) is a miss

"Caught by" names the doctest test case that exists for that mistake; its hint for the
student is in tests/hints/mistakes.json under the same name. The patches hold solution code:
the starter kit leaves them out (kit.py), and this command runs in the reference tree only.

usage: ./workbook mutants [N.M | NN | N.M-name ...] [--list] [--check]
       ./workbook mutants --safeguards [NAME ...] [--list] [--check]
       ./workbook mutants --generate [N.M | NN ...] [--list] [--summary]
  (none: every mutant; N.M: an exercise's; NN: a step's; N.M-name: one mutant, in the
  order given)
  --list   the catalogue
  --check  only check the catalogue: every patch applies, names its case, has a hint
  --safeguards  the hard cases' safeguards removed instead (tests/safeguards,
           tools/grading/safeguards.py, which ./workbook runs for it): exactly the named
           hard cases must fail
  --generate  the mechanical mutants of each solution body instead, and the mutation
           score per exercise (tools/grading/mutant_generator.py, which ./workbook runs
           for it)

Each mutant is applied to a private copy of the tree (build/mutants/tree, kept between
runs so that its build is incremental), the exercise's test program alone is built, the
exercise's ctest label alone is run, and the patch is reverted. A mutant is caught when its
own test case fails; the table says which cases failed. Each step's reference runs first:
its exercise tests must pass, or every mutant would look caught.
"""
import glob
import json
import os
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass

from . import ROOT
from .. import build
from .kit import tracked_files

MUTANTS_DIR = "tests/mutants"
HINTS = "tests/hints/mistakes.json"
NAME = re.compile(r"^(\d+\.\d+)-([a-z0-9][a-z0-9-]*)\.patch$")
# Seconds per test case: a mutant may loop (a wrong bound, a budget never met).
TEST_TIMEOUT = 60


@dataclass
class Mutant:
    id: str  # "1.4-no-v-rejection"
    exercise: str  # "1.4"
    path: str  # absolute
    mistake: str = ""
    caught_by: str = ""

    @property
    def step(self):
        return int(self.exercise.split(".")[0])

    @property
    def key(self):
        return tuple(int(x) for x in self.exercise.split(".")) + (self.id,)


def read_mutant(path):
    name = os.path.basename(path)
    m = NAME.match(name)
    if not m:
        raise ValueError(f"{name}: a mutant is named N.M-short-name.patch")
    mutant = Mutant(name[: -len(".patch")], m.group(1), path)
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.startswith("diff --git") or line.startswith("--- "):
                break
            if line.startswith("Mistake:"):
                mutant.mistake = line.split(":", 1)[1].strip()
            elif line.startswith("Caught by:"):
                mutant.caught_by = line.split(":", 1)[1].strip()
    return mutant


def catalogue(root=ROOT):
    """Every mutant in tests/mutants/, by exercise."""
    paths = glob.glob(os.path.join(root, MUTANTS_DIR, "*.patch"))
    return sorted((read_mutant(p) for p in paths), key=lambda m: m.key)


def select(mutants, wanted):
    """The mutants of the exercises (1.4), steps (01) or single mutants (1.4-name) asked for."""
    if not wanted:
        return mutants
    chosen = []
    for w in wanted:
        found = [m for m in mutants
                 if m.id == w or m.exercise == w or (re.fullmatch(r"\d\d?", w) and m.step == int(w))]
        if not found:
            raise SystemExit(f"mutants: no mutant for '{w}' (./workbook mutants --list)")
        chosen += [m for m in found if m not in chosen]
    return chosen


def git_apply(tree, patch, *flags):
    """git apply in a folder that is not a repository (the discovery stops at the folder).
    When the context lines have changed around the mistake (the solution was edited nearby),
    the changed lines alone must match (-C0), near where the patch says."""
    env = dict(os.environ, GIT_CEILING_DIRECTORIES=os.path.dirname(os.path.abspath(tree)))
    r = subprocess.run(["git", "apply", *flags, patch], cwd=tree, env=env,
                       capture_output=True, text=True)
    if r.returncode != 0:
        loose = subprocess.run(["git", "apply", "-C0", *flags, patch], cwd=tree, env=env,
                               capture_output=True, text=True)
        if loose.returncode == 0:
            return loose
    return r


def test_case_names(root=ROOT):
    """Every doctest TEST_CASE name in the tests' sources (string literals joined)."""
    names = set()
    for path in glob.glob(os.path.join(root, "tests", "*.cpp")):
        with open(path, encoding="utf-8") as f:
            text = f.read()
        for m in re.finditer(r"TEST_CASE\s*\(((?:\s*\"(?:[^\"\\]|\\.)*\")+)", text):
            names.add("".join(re.findall(r"\"((?:[^\"\\]|\\.)*)\"", m.group(1))))
    return names


def check_catalogue(root=ROOT, tree=None):
    """Problems with the catalogue (empty when sound): each patch applies to the reference
    (`tree`, default the root), names a test case that exists, and has that case's hint."""
    problems = []
    try:
        with open(os.path.join(root, HINTS), encoding="utf-8") as f:
            hints = json.load(f)
    except (OSError, ValueError) as e:
        return [f"{HINTS}: {e}"]
    cases = test_case_names(root)
    mutants = catalogue(root)
    if not mutants:
        problems.append(f"{MUTANTS_DIR}: no mutants")
    seen = {}
    for m in mutants:
        # One case per mistake: its failure names the mistake, and the hint is the mistake's.
        if m.caught_by and m.caught_by in seen:
            problems.append(f"{m.id}: '{m.caught_by}' already catches {seen[m.caught_by]}")
        seen.setdefault(m.caught_by, m.id)
        if not m.mistake:
            problems.append(f"{m.id}: no 'Mistake:' line")
        if not m.caught_by:
            problems.append(f"{m.id}: no 'Caught by:' line")
            continue
        if m.caught_by not in cases:
            problems.append(f"{m.id}: no test case named '{m.caught_by}'")
        hint = hints.get(m.caught_by)
        if not hint:
            problems.append(f"{m.id}: no hint in {HINTS} for '{m.caught_by}'")
        elif hint.get("exercise") != m.exercise or not hint.get("hint"):
            problems.append(f"{m.id}: the hint for '{m.caught_by}' is not exercise {m.exercise}'s")
        r = git_apply(tree or root, m.path, "--check")
        if r.returncode != 0:
            problems.append(f"{m.id}: does not apply: {r.stderr.strip().splitlines()[0] if r.stderr.strip() else ''}")
    for case, hint in hints.items():
        if case not in cases:
            problems.append(f"{HINTS}: '{case}' is not a test case")
    return problems


# The private tree ----------------------------------------------------------------------------


def sync_tree(root, tree):
    """Makes `tree` a copy of the root's tracked files; unchanged files keep their times, so
    the copy's build redoes only what changed."""
    files = set(tracked_files(root))
    for rel in sorted(files):
        src, dst = os.path.join(root, rel), os.path.join(tree, rel)
        if os.path.isfile(dst) and os.path.getsize(src) == os.path.getsize(dst):
            with open(src, "rb") as a, open(dst, "rb") as b:
                if a.read() == b.read():
                    continue
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        # A new time, not the source's: an object built from a mutant is newer than the
        # reference file, and the build must see the file change back.
        shutil.copyfile(src, dst)
        shutil.copymode(src, dst)
    for base, dirs, names in os.walk(tree):
        rel_base = os.path.relpath(base, tree)
        if rel_base == "build" or rel_base.startswith("build" + os.sep):
            dirs[:] = []
            continue
        for n in names:
            rel = os.path.normpath(os.path.join(rel_base, n))
            if rel not in files:
                os.remove(os.path.join(base, n))


def release_tree(tree):
    """The private tree's release build (tools/build.py). No step programs: the exercise
    suites need only the step's library. No link-time optimisation either: it would add a
    slower link to every mutant's build."""
    return build.Tree.of_preset(tree, "release", BOXES_TESTS_BUILD_PROGRAMS="OFF", BOXES_LTO="OFF")


def build_dir(tree):
    return release_tree(tree).build


def configure(tree, log):
    return build.configure(release_tree(tree), log=log).ok


def build_and_test(tree, step, exercises, log, title):
    """Builds test_stepNN and runs the exercises' ctest labels: (status, failing cases), the
    status "passed", "failed", "no build" or "no tests"."""
    target = f"test_step{step:02d}"
    log.write(f"\n==== {title}: build {target}\n")
    log.flush()
    # Two jobs: the machine is shared, and one mutant rebuilds a file or two.
    if not build.build(release_tree(tree), [target], jobs=2, log=log).ok:
        return "no build", []
    label = "^exercise (" + "|".join(re.escape(e) for e in exercises) + ")$"
    t = subprocess.run(["ctest", "--test-dir", build_dir(tree), "-L", label,
                        "--timeout", str(TEST_TIMEOUT), "--output-on-failure"],
                       capture_output=True, text=True)
    # A looping mutant's output is cut: the failing cases' names are in the summary.
    out = t.stdout if len(t.stdout) < 200000 else t.stdout[:100000] + "\n[...]\n" + t.stdout[-100000:]
    log.write(out + t.stderr)
    if "No tests were found" in t.stdout + t.stderr:
        return "no tests", []
    failing = re.findall(r"^\s*\d+ - test_step\d+: ?(.*?) \((?:Failed|Timeout|SEGFAULT|"
                         r"Subprocess aborted|Exception|Child aborted|ILLEGAL|BUS|NUMERICAL|OTHER_FAULT)\)",
                         t.stdout, re.M)
    return ("passed" if t.returncode == 0 else "failed"), failing


def patched_files(patch):
    with open(patch, encoding="utf-8") as f:
        return [l[6:].strip() for l in f if l.startswith("+++ b/")]


def applied_marker(tree):
    return os.path.join(os.path.dirname(tree), "applied.txt")


def recover(tree):
    """After a run that was stopped with a mutant applied: the sync restores the file's
    text, and a new time makes the build recompile it."""
    marker = applied_marker(tree)
    if not os.path.isfile(marker):
        return
    with open(marker, encoding="utf-8") as f:
        patch = f.read().strip()
    if os.path.isfile(patch):
        for rel in patched_files(patch):
            if os.path.isfile(os.path.join(tree, rel)):
                os.utime(os.path.join(tree, rel))
    os.remove(marker)


def run_one(tree, mutant, log):
    """Applies, builds, tests, reverts. Returns (status, failing test cases)."""
    with open(applied_marker(tree), "w", encoding="utf-8") as f:
        f.write(mutant.path)
    r = git_apply(tree, mutant.path)
    if r.returncode != 0:
        os.remove(applied_marker(tree))
        return "no apply", [r.stderr.strip()]
    try:
        status, failing = build_and_test(tree, mutant.step, [mutant.exercise], log, mutant.id)
        return {"passed": "MISSED", "failed": "caught"}.get(status, status), failing
    finally:
        r = git_apply(tree, mutant.path, "-R")
        if r.returncode != 0:
            raise SystemExit(f"mutants: could not revert {mutant.id}: {r.stderr.strip()}")
        os.remove(applied_marker(tree))


def table(rows):
    """rows: (mutant, exercise, status, cases) -> text."""
    head = ("mutant", "exercise", "result", "failing test case")
    lines = [head] + [(m, e, s, "; ".join(c) if c else "-") for m, e, s, c in rows]
    w = [max(len(r[i]) for r in lines) for i in range(3)]
    return "\n".join(f"{r[0]:<{w[0]}}  {r[1]:<{w[1]}}  {r[2]:<{w[2]}}  {r[3]}" for r in lines)


def list_or_check(tool, noun, selected, total, describe, check, flags, stop_on_problems):
    """What --list, --check and a broken catalogue make of a run (shared with safeguards.py):
    (an exit status or None when the run goes on, the catalogue's problems). describe(item)
    is its --list line, check() finds the problems (printed; with stop_on_problems they end
    the run)."""
    if "--list" in flags:
        for item in selected:
            print(describe(item))
        return 0, []
    problems = check()
    for p in problems:
        print(f"{tool}: {p}", file=sys.stderr)
    if "--check" in flags:
        print(f"{tool}: {total} {noun}, {'sound' if not problems else f'{len(problems)} problems'}")
        return (1 if problems else 0), problems
    return (1 if problems and stop_on_problems else None), problems


def private_tree():
    """The reference tree's private copy under build/mutants/, synced, a patch left applied
    by an interrupted run taken back."""
    tree = os.path.join(ROOT, "build", "mutants", "tree")
    os.makedirs(tree, exist_ok=True)
    sync_tree(ROOT, tree)
    recover(tree)
    return tree


def main(argv):
    args = [a for a in argv if not a.startswith("-")]
    flags = [a for a in argv if a.startswith("-")]
    for f in flags:
        if f == "--safeguards":
            print("mutants: the safeguards are python3 -m tools.grading.safeguards (./workbook mutants "
                  "--safeguards runs it)", file=sys.stderr)
            return 2
        if f not in ("--list", "--check", "-h", "--help"):
            print(f"mutants: unknown option '{f}' (use: mutants [N.M ...] [--list] [--check])",
                  file=sys.stderr)
            return 2
    if "-h" in flags or "--help" in flags:
        print(__doc__.split("usage:", 1)[1].split("\n\n")[0].strip())
        return 0
    if not os.path.isfile(os.path.join(ROOT, "tools", "grading", "grade.py")):
        print("mutants: the catalogue runs in the reference tree (with the solutions), not in a "
              "starter kit", file=sys.stderr)
        return 2
    mutants = select(catalogue(), args)
    status, problems = list_or_check("mutants", "mutants", mutants, len(catalogue()),
                                     lambda m: f"{m.id:<40} {m.mistake}", check_catalogue,
                                     flags, stop_on_problems=False)
    if status is not None:
        return status
    tree = private_tree()
    log_path = os.path.join(ROOT, "build", "mutants", "log.txt")
    rows, started = [], time.monotonic()
    with open(log_path, "w", encoding="utf-8") as log:
        if not configure(tree, log):
            print(f"mutants: configuring the private tree failed (see {log_path})", file=sys.stderr)
            return 1
        # Each step's reference first: its suites must pass, or every mutant would seem caught.
        broken, checked = set(), set()
        for i, m in enumerate(mutants):
            if m.step not in checked:
                checked.add(m.step)
                wanted = sorted({x.exercise for x in mutants if x.step == m.step})
                print(f"[mutants] the reference's tests of step {m.step:02d}", file=sys.stderr,
                      flush=True)
                status, cases = build_and_test(tree, m.step, wanted, log, f"reference {m.step:02d}")
                if status != "passed":
                    print(f"mutants: the reference fails step {m.step:02d}'s exercise tests "
                          f"({status}: {'; '.join(cases) or 'see the log'}); its mutants are skipped",
                          file=sys.stderr, flush=True)
                    broken.add(m.step)
            if m.step in broken:
                rows.append((m.id, m.exercise, "reference fails", []))
                continue
            print(f"[mutants] {i + 1}/{len(mutants)} {m.id}", file=sys.stderr, flush=True)
            status, cases = run_one(tree, m, log)
            if status == "caught" and m.caught_by not in cases:
                status = "caught, not by its case"
            rows.append((m.id, m.exercise, status, cases))
            print(f"[mutants] {m.id}: {status} ({'; '.join(cases) or '-'})", file=sys.stderr,
                  flush=True)
    print(table(rows))
    bad = [r for r in rows if r[2] != "caught"]
    print(f"\n{len(rows) - len(bad)} of {len(rows)} mutants caught by their own test case "
          f"in {time.monotonic() - started:.0f} s (log: {os.path.relpath(log_path, ROOT)})")
    if problems:
        print(f"mutants: the catalogue has {len(problems)} problems (above)", file=sys.stderr)
    return 1 if bad or problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
