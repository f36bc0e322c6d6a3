#!/usr/bin/python3
"""End-to-end tests of the starter kit and of grading (ctest label "grading").

usage: tests/grading_test.py SCENARIO WORK_DIR
  kit            the kit has no solution line left, a stub per exercise, everything else equal
  reference      the reference tree scores full points
  kit-zero       the starter kit scores zero, each failure naming its exercise
  one-solved     a kit with one exercise solved scores exactly that exercise's points
  compile-error  a step that does not compile scores zero with the compiler's error; the
                 other graded steps keep their points
  hidden         an instructor's hidden tests count, and a hanging test case times out
  each-solved    (by hand, not in ctest) each exercise solved alone scores exactly its points

The steps are discovered, not named: grading scenarios use the first step with exercises
(and the last one for the compile error), so they keep working as steps are added. All
grading scenarios share one grading build in WORK_DIR (ctest runs them one at a time).
"""
import os
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
from exercises import BEGIN, END, exercises, step_dirs, step_sources  # noqa: E402
from kit import strip_solutions, write_kit  # noqa: E402

failures = []


def check(condition, message):
    print(("ok    " if condition else "FAIL  ") + message)
    if not condition:
        failures.append(message)


def steps_with_exercises():
    numbers = sorted({f"{e.step:02d}" for e in exercises(ROOT)})
    return numbers


def student_tree(dest, keep=None, break_step=None):
    """A student's tree with only steps/: the reference (keep=None) or the kit with the
    exercises in `keep` solved; `break_step` gets a compile error in its exercise file."""
    for path in step_sources(ROOT):
        rel = os.path.relpath(path, ROOT)
        with open(path, encoding="utf-8") as f:
            text = f.read()
        if keep is not None:
            text, _ = strip_solutions(text, path, ROOT, keep)
        os.makedirs(os.path.dirname(os.path.join(dest, rel)), exist_ok=True)
        with open(os.path.join(dest, rel), "w", encoding="utf-8") as f:
            f.write(text)
    if break_step:
        target = next(e.path for e in exercises(ROOT) if f"{e.step:02d}" == break_step)
        with open(os.path.join(dest, target), "a", encoding="utf-8") as f:
            f.write("\nthis line is not C++;\n")
        return target
    return None


def grade(student, work, steps, junit):
    cmd = [sys.executable, os.path.join(ROOT, "tools", "grade.py"), student, "--work", work,
           "--steps", ",".join(steps), "--junit", junit, "--timeout", "120"]
    r = subprocess.run(cmd, capture_output=True, text=True)
    print(r.stdout)
    if r.returncode != 0:
        print(r.stderr)
    check(r.returncode == 0, f"grade.py exits 0 for {os.path.basename(student)}")
    results = {}
    if os.path.exists(junit):
        for case in ET.parse(junit).getroot().iter("testcase"):
            failure = case.find("failure")
            results[case.get("classname").split()[-1]] = (failure is None,
                                                          "" if failure is None else failure.get("message"))
    return r.stdout, results


def points(ids):
    by_id = {e.id: e.points for e in exercises(ROOT)}
    return sum(by_id[i] for i in ids)


def scenario_kit(work):
    dest = os.path.join(work, "kit")
    shutil.rmtree(dest, ignore_errors=True)
    stubbed = write_kit(dest, ROOT)
    all_ex = exercises(ROOT)
    check(sorted(e.id for e in stubbed) == sorted(e.id for e in all_ex), "every exercise is stubbed")
    for path in step_sources(ROOT):
        rel = os.path.relpath(path, ROOT)
        with open(path, encoding="utf-8") as f:
            ref = f.read().split("\n")
        with open(os.path.join(dest, rel), encoding="utf-8") as f:
            kit = f.read().split("\n")
        # The kit's file is the reference outside the blocks, each block a stub.
        outside, inside, block = [], [], False
        for line in ref:
            if BEGIN.match(line):
                block = True
                outside.append("<stub>")
            elif END.match(line):
                block = False
            elif block:
                inside.append(line)
            else:
                outside.append(line)
        kept, in_stub = [], False
        for line in kit:
            if "// TODO: your solution" in line:
                in_stub = True
                kept.append("<stub>")
            elif in_stub:
                in_stub = "throw NotImplemented(" not in line
            elif line != '#include "core/exercise.hpp"' or line in ref:
                kept.append(line)
        check(kept == outside, f"{rel}: unchanged outside the solution blocks")
        leaked = [l for l in inside if l.strip() and l.strip() not in {o.strip() for o in outside}
                  and l in kit]
        check(not leaked, f"{rel}: no solution line survives ({len(inside)} lines removed)")
    for e in all_ex:
        with open(os.path.join(dest, e.path), encoding="utf-8") as f:
            check(f'throw NotImplemented("{e.id}");' in f.read(), f"exercise {e.id} throws NotImplemented")
    check(not os.path.exists(os.path.join(dest, "build")), "no build output in the kit")
    check(not os.path.exists(os.path.join(dest, "tools", "grade.py")), "no grading in the kit")


def scenario_reference(work):
    first = steps_with_exercises()[0]
    out, results = grade(ROOT, work, [first], os.path.join(work, "reference.xml"))
    ids = [e.id for e in exercises(ROOT) if f"{e.step:02d}" == first]
    for i in ids:
        check(results.get(i, (False, ""))[0], f"reference: exercise {i} passes {results.get(i)}")
    check(f"Grade: {points(ids)} of {points(ids)} points" in out, "reference: full points")


def scenario_kit_zero(work):
    first = steps_with_exercises()[0]
    with tempfile.TemporaryDirectory() as student:
        student_tree(student, keep=())
        # A student's own copies of the tests and of the points never count: tests that
        # always pass and a marker worth 100 points change nothing.
        os.makedirs(os.path.join(student, "tests"))
        for e in exercises(ROOT):
            with open(os.path.join(student, "tests", f"step{e.step:02d}_fake.cpp"), "a") as f:
                f.write(f'TEST_SUITE("exercise {e.id}") {{ TEST_CASE("fake {e.id}") {{}} }}\n')
            path = os.path.join(student, e.path)
            with open(path, encoding="utf-8") as f:
                text = f.read()
            with open(path, "w", encoding="utf-8") as f:
                f.write(text.replace(f"EXERCISE {e.id}:", f"EXERCISE {e.id}: (100 points)//", 1))
        out, results = grade(student, work, [first], os.path.join(work, "kit.xml"))
    ids = [e.id for e in exercises(ROOT) if f"{e.step:02d}" == first]
    for i in ids:
        passed, message = results.get(i, (True, ""))
        check(not passed, f"kit: exercise {i} fails")
        check(f"exercise {i} is not implemented yet" in message or "is not implemented yet" in message,
              f"kit: the failure names a missing exercise: {message!r}")
    check(f"Grade: 0 of {points(ids)} points" in out, "kit: zero points")


def scenario_one_solved(work):
    first = steps_with_exercises()[0]
    ids = [e.id for e in exercises(ROOT) if f"{e.step:02d}" == first]
    solved = "1.4" if "1.4" in ids else ids[-1]
    with tempfile.TemporaryDirectory() as student:
        student_tree(student, keep={solved})
        out, results = grade(student, work, [first], os.path.join(work, "one.xml"))
    for i in ids:
        check(results.get(i, (None,))[0] == (i == solved), f"one solved: exercise {i} "
              f"{'passes' if i == solved else 'fails'}")
    check(f"Grade: {points([solved])} of {points(ids)} points" in out,
          f"one solved: exactly the {points([solved])} points of exercise {solved}")


def scenario_compile_error(work):
    numbers = steps_with_exercises()
    broken = numbers[-1]  # the last step: no later step links it
    graded = sorted({numbers[0], broken})
    with tempfile.TemporaryDirectory() as student:
        path = student_tree(student, break_step=broken)
        out, results = grade(student, work, graded, os.path.join(work, "broken.xml"))
    for e in exercises(ROOT):
        step = f"{e.step:02d}"
        if step not in graded:
            continue
        passed, message = results.get(e.id, (None, ""))
        if step == broken:
            check(passed is False and message.startswith("does not compile: ")
                  and os.path.basename(path) in message and "error" in message,
                  f"compile error: exercise {e.id} scores zero with the compiler's first error: {message!r}")
        else:
            check(passed is True, f"compile error elsewhere: exercise {e.id} still passes")
    if len(graded) == 1:
        print("note: only one step has exercises; the other steps' scores are checked once there are more")


def scenario_hidden(work):
    """An instructor's hidden tests count for their exercise, and a test case that hangs is
    stopped by the time limit."""
    first = steps_with_exercises()[0]
    ids = [e.id for e in exercises(ROOT) if f"{e.step:02d}" == first]
    failing, hanging = ids[0], ids[-1]
    with tempfile.TemporaryDirectory() as hidden:
        with open(os.path.join(hidden, f"step{first}_hidden.cpp"), "w") as f:
            f.write("#include <doctest/doctest.h>\n#include <chrono>\n#include <thread>\n"
                    f'TEST_SUITE("exercise {failing}") {{\n'
                    '    TEST_CASE("hidden: an instructor check") { CHECK(1 + 1 == 3); }\n}\n'
                    f'TEST_SUITE("exercise {hanging}") {{\n'
                    '    TEST_CASE("hidden: a test that never ends") {\n'
                    "        for (;;) std::this_thread::sleep_for(std::chrono::milliseconds(10));\n"
                    "    }\n}\n")
        cmd = [sys.executable, os.path.join(ROOT, "tools", "grade.py"), ROOT, "--work", work,
               "--steps", first, "--junit", os.path.join(work, "hidden.xml"), "--timeout", "3",
               "--hidden", hidden]
        r = subprocess.run(cmd, capture_output=True, text=True)
    print(r.stdout, r.stderr)
    check(r.returncode == 0, "grade.py with --hidden exits 0")
    lines = {l.split()[0]: l for l in r.stdout.splitlines() if l[:1].isdigit()}
    check("hidden: an instructor check" in lines.get(failing, "") and "FAILED" in lines.get(failing, ""),
          f"hidden: exercise {failing} fails on the hidden check")
    check("time limit" in lines.get(hanging, ""), f"hidden: exercise {hanging} stops at the time limit")
    others = [i for i in ids if i not in (failing, hanging)]
    check(all("passed" in lines.get(i, "") for i in others), "hidden: the other exercises pass")
    expected = points(others)
    check(f"Grade: {expected} of {points(ids)} points" in r.stdout, f"hidden: {expected} points")


def scenario_each_solved(work):
    """Not in ctest (a rebuild per exercise): every exercise solved alone in the kit scores
    exactly its points, i.e. no exercise's tests lean on another exercise."""
    for number in steps_with_exercises():
        ids = [e.id for e in exercises(ROOT) if f"{e.step:02d}" == number]
        for solved in ids:
            with tempfile.TemporaryDirectory() as student:
                student_tree(student, keep={solved})
                out, results = grade(student, work, [number], os.path.join(work, "each.xml"))
            wrong = [i for i in ids if results.get(i, (None,))[0] != (i == solved)]
            check(not wrong, f"only {solved} solved: " + ("exactly its points" if not wrong else
                  "; ".join(f"{i} {'fails' if i == solved else 'passes'}: {results.get(i, ('', ''))[1]}"
                            for i in wrong)))


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    scenario, work = sys.argv[1], os.path.abspath(sys.argv[2])
    os.makedirs(work, exist_ok=True)
    {"kit": scenario_kit, "reference": scenario_reference, "kit-zero": scenario_kit_zero,
     "one-solved": scenario_one_solved, "compile-error": scenario_compile_error,
     "hidden": scenario_hidden, "each-solved": scenario_each_solved}[scenario](work)
    print(f"{len(failures)} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
