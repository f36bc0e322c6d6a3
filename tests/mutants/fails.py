"""Records what each catalogued mistake fails, check by check, in its entry of
tests/hints/mistakes.json ("fails": {"test case | the check's expression": times}).
`./workbook check` names the mistake a student made from these records: of the catalogued
cases that fail, the one whose mistake fails most alike (tools/check.py mistake_case).

usage: python3 -m tests.mutants.fails [N.M | NN | N.M-name ...]
       (from the reference tree's root; default: every mistake)

Each mistake (tests/mutants/N.M-name.patch) is applied to the mutants' private copy of the
tree (build/mutants/tree, tools/grading/mutants.py), the exercise's test program built
there with check's preset (student), its suite run as check runs it (doctest's XML), and
the patch taken back. Run it after a
change to an exercise's tests or to a patch; a mistake that its own case does not catch is
reported and its record left as it was.
"""
import json
import os
import sys
from collections import Counter

from tools import ROOT
from tools import build as building
from tools.check import parse_cases, run_suite
from tools.grading import mutants

HINTS = os.path.join(ROOT, "tests", "hints", "mistakes.json")


def failures(tree, target, mutant, log):
    """{"case | check": times} of the mutant's exercise, or raises RuntimeError saying why."""
    with open(mutants.applied_marker(tree), "w", encoding="utf-8") as f:
        f.write(mutant.path)
    r = mutants.git_apply(tree, mutant.path)
    if r.returncode != 0:
        os.remove(mutants.applied_marker(tree))
        raise RuntimeError(f"does not apply: {r.stderr.strip()}")
    try:
        b = building.build(target, [f"test_step{mutant.step:02d}"], jobs=2, log=log)
        if not b.ok:
            raise RuntimeError(f"does not build: {b.error}")
        binary = os.path.join(target.build, "tests", f"test_step{mutant.step:02d}")
        kind, data, detail = run_suite(binary, mutant.exercise, mutants.TEST_TIMEOUT)
        cases = parse_cases(data) if data else None
        if kind != "ok" or cases is None:
            raise RuntimeError(f"its tests {kind} {detail}")
        return Counter(key for c in cases if not c["passed"] for key in c["checks"])
    finally:
        r = mutants.git_apply(tree, mutant.path, "-R")
        if r.returncode != 0:
            raise SystemExit(f"fails: could not take back {mutant.id}: {r.stderr.strip()}")
        os.remove(mutants.applied_marker(tree))


def main(argv):
    chosen = mutants.select(mutants.catalogue(), argv)
    with open(HINTS, encoding="utf-8") as f:
        hints = json.load(f)
    tree = mutants.private_tree()
    problems = 0
    with open(os.path.join(ROOT, "build", "mutants", "fails-log.txt"), "w", encoding="utf-8") as log:
        # The student's preset, as check builds: the same flags, the same failures.
        target = building.Tree.of_preset(tree, "student")
        if not building.configure(target, log=log).ok:
            print("fails: configuring the private tree failed (build/mutants/fails-log.txt)", file=sys.stderr)
            return 1
        for i, m in enumerate(chosen):
            try:
                found = failures(tree, target, m, log)
            except RuntimeError as e:
                print(f"[fails] {m.id}: {e}", file=sys.stderr)
                problems += 1
                continue
            if not any(key.startswith(f"{m.caught_by} | ") for key in found):
                print(f"[fails] {m.id}: its case '{m.caught_by}' does not fail; record kept", file=sys.stderr)
                problems += 1
                continue
            hints[m.caught_by]["fails"] = dict(found)
            print(f"[fails] {i + 1}/{len(chosen)} {m.id}: {sum(found.values())} failed checks in "
                  f"{len({k.split(' | ')[0] for k in found})} cases", file=sys.stderr, flush=True)
            with open(HINTS, "w", encoding="utf-8") as f:  # after each: a stopped run keeps what it did
                f.write(json.dumps(hints, indent=2) + "\n")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
