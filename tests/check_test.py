#!/usr/bin/python3
"""The student's loop end to end (ctest label "grading"): `./workbook check` in a fresh
starter kit, as a student uses it.

usage: python3 -m tests.check_test WORK_DIR [BUILD_DIR]
  BUILD_DIR: this tree's release build, whose step 01 program renders the kit's reference
  pictures (default build/release)

One kit, one build in it (check's own, build/student), the cases in order:
  fresh        `check`: 0 points, every exercise of step 01 "not started", the later steps
               not checked, the next one is 1.1 with its file and line (the line of its
               EXERCISE marker); only step 01's test program and what it needs were built
  exam         `exam --list`: only the exam program and what it needs were built
  hang         exercise 1.1 that never returns: one "timed out" verdict, no picture render
  correct 1.4  the reference's 1.4 copied into the kit: `check 1.4` passes, and its picture
               is the reference's
  wrong 1.4    the catalogued mistake without the u + v > 1 rejection: `check 1.4` fails,
               names the mistake's test case, `--hint` gives the mistake's hint, and
               out/check/1.4.png marks the extra pixels (as many as it says)
  hints        three mistakes that fail more than their own case (2.1 with the sign of d
               flipped on the negative faces, 3.4 with the slide's bmin.y typo, 3.5 with
               strict comparisons): `--hint` names each one's own mistake
  watch        `check 1.4 --watch`: an edit (the mistake fixed) starts a new run within two
               seconds, and that run passes; by polling too when inotifywait is installed

check builds the steps it checks (01, then 02 and 03 for the hints) at the grader's -O1.
The kit is written anew each run (a fresh kit), in WORK_DIR/kit.
"""
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

from tools import ROOT
from tools import png
from tools.grading.exercises import exercises
from tools.grading.kit import strip_solutions, write_kit
from tools.grading.mutants import git_apply, read_mutant
from tools import pictures
from tools.pictures import HEIGHT, MARK, TOLERANCE, WIDTH, render_references

EXERCISE = "1.4"
MISTAKE = os.path.join(ROOT, "tests", "mutants", "1.4-no-uv-sum-rejection.patch")
# Mistakes whose own test case is not the first one they fail: (exercise, the patch's text
# or a catalogued patch, the test case whose hint names the mistake). The first is not in
# the catalogue (whose cases each catch one mistake): the sign of d flipped on the negative
# faces only fails the same cases as 2.1-half-extent-sign, and must get its hint.
NEGATIVE_FACES_D = """--- a/steps/02_box/box.cpp
+++ b/steps/02_box/box.cpp
@@ -49,3 +49,4 @@
         Vec3T<T> n = sign * box.axes[size_t(axis)];
-        planes[size_t(face)] = PlaneT<T>{n, -(glm::dot(n, box.centre) + box.halfExtents[axis])};
+        T d = glm::dot(n, box.centre) + box.halfExtents[axis];
+        planes[size_t(face)] = PlaneT<T>{n, sign * -d};
     }
"""
HINT_CASES = [
    ("2.1", NEGATIVE_FACES_D, "face planes: every face passes through the centre plus or minus its half extent"),
    ("3.4", os.path.join(ROOT, "tests", "mutants", "3.4-slide-y-line.patch"), None),
    ("3.5", os.path.join(ROOT, "tests", "mutants", "3.5-strict.patch"), None),
]
WATCH_LIMIT = 2.0  # seconds from a save to the new run

failures = []


def check(condition, message):
    print(("ok    " if condition else "FAIL  ") + message, flush=True)
    if not condition:
        failures.append(message)


def run_check(kit, *args):
    """./workbook check ARGS in the kit: (exit code, output)."""
    started = time.monotonic()
    r = subprocess.run(["./workbook", "check", *args], cwd=kit, capture_output=True, text=True,
                       timeout=900)
    out = r.stdout + r.stderr
    print(f"--- ./workbook check {' '.join(args)}: exit {r.returncode}, "
          f"{time.monotonic() - started:.1f} s\n{out}", flush=True)
    return r.returncode, out


def row(out, exercise_id):
    """The table's line of one exercise, or ""."""
    m = re.search(rf"^  {re.escape(exercise_id)}\s+\d+/\d+\s+.*$", out, re.M)
    return m.group(0) if m else ""


def solve(kit, exercise):
    """The kit's file of the exercise with the reference's solution of that exercise only."""
    path = os.path.join(ROOT, exercise.path)
    with open(path, encoding="utf-8") as f:
        text, _ = strip_solutions(f.read(), path, ROOT, keep={exercise.id})
    with open(os.path.join(kit, exercise.path), "w", encoding="utf-8") as f:
        f.write(text)
    return text


def marked(composite):
    """Reads check's picture (a strip of names over yours | reference | differences): its
    size, the pixels where the first two panels differ beyond the tolerance, and whether
    the third panel marks exactly those: each one magenta, and no magenta at all when none
    differ (the rings around a marked pixel are magenta too, so they are not counted)."""
    w, h, rows = png.read(composite)
    gap = (w - 3 * WIDTH) // 2
    body = rows[h - HEIGHT :]
    mark = bytes(MARK)

    def pixel(panel, x, y):
        i = 3 * (panel * (WIDTH + gap) + x)
        return body[y][i : i + 3]

    differ = [(x, y) for y in range(HEIGHT) for x in range(WIDTH)
              if max(abs(a - b) for a, b in zip(pixel(0, x, y), pixel(1, x, y))) > TOLERANCE]
    magenta = sum(pixel(2, x, y) == mark for y in range(HEIGHT) for x in range(WIDTH))
    marks_them = all(pixel(2, x, y) == mark for x, y in differ) and (magenta > 0) == bool(differ)
    return (w, h), len(differ), marks_them


def built_outputs(kit):
    """What the kit's build has built so far (ninja's log), as paths in the build folder."""
    path = os.path.join(kit, "build", "student", ".ninja_log")
    with open(path, encoding="utf-8") as f:
        return {line.split("\t")[3] for line in f if not line.startswith("#") and line.count("\t") >= 4}


def needed_for(kit, target, output):
    """The target, its output file and everything ninja builds it from."""
    build = os.path.join(kit, "build", "student")
    r = subprocess.run(["ninja", "-C", build, "-t", "inputs", target], capture_output=True, text=True)
    needed = set(r.stdout.split()) | {output}
    # `-t inputs` names a phony edge but not what it stands for: the precompiled header's
    # object library (core/boxes_pch, which every library waits for) is its object.
    q = subprocess.run(["ninja", "-C", build, "-t", "query", *sorted(needed)], capture_output=True, text=True)
    section = None  # the last header line: a target, "input: RULE" or "outputs:"
    for line in q.stdout.splitlines():
        if not line.startswith("    "):
            section = line.strip()
        elif section == "input: phony":
            needed.add(line.split()[-1])  # a path, after "|" or "||" when implicit or order-only
    return needed


def case_fresh(kit, ex):
    step = [e for e in ex if e.step == 1]
    rc, out = run_check(kit)
    check(rc == 0, f"fresh kit: check 01 exits 0 (nothing attempted), exit {rc}")
    total = sum(e.points for e in step)
    check(re.search(rf"^  total\s+0/{total}\s+points", out, re.M) is not None, f"fresh kit: 0 of {total} points")
    check(all("not started" in row(out, e.id) for e in step), "fresh kit: every exercise of step 01 is not started")
    first = step[0]
    check(f"Next: exercise {first.id}:" in out, f"fresh kit: the next exercise is {first.id}")
    m = re.search(r"^  where: (\S+):(\d+)$", out, re.M)
    where_ok = False
    if m and os.path.isfile(os.path.join(kit, m.group(1))):
        with open(os.path.join(kit, m.group(1)), encoding="utf-8") as f:
            lines = f.read().split("\n")
        n = int(m.group(2))
        where_ok = 1 <= n <= len(lines) and f"EXERCISE {first.id}:" in lines[n - 1]
    check(where_ok, f"fresh kit: the file and line given hold exercise {first.id}'s marker ({m and m.group(0).strip()})")
    later = sum(e.points for e in ex if e.step > 1)
    check(re.search(r"^  \S+: not checked yet \(\d+ exercises of steps 02", out, re.M) is not None,
          "fresh kit: the later steps are not checked yet, and the table says so")
    # Step 01's tests, then (after the verdict) step 01's program for the pictures; ninja's
    # bookkeeping (build.ninja, CMake's check of its globs) besides.
    allowed = needed_for(kit, "test_step01", "tests/test_step01") | \
        needed_for(kit, "01_triangle", "steps/01_triangle/01_triangle") | \
        {"build.ninja", os.path.join(kit, "build", "student", "CMakeFiles", "cmake.verify_globs")}
    extra = sorted(built_outputs(kit) - allowed)
    check(not extra and later > 0,
          f"fresh kit: only step 01's test program, its program and what they need were built ({extra[:5]})")


def case_exam(kit):
    """`./workbook exam` builds the exam program and what it needs, nothing else."""
    before = built_outputs(kit)
    started = time.monotonic()
    r = subprocess.run(["./workbook", "exam", "--list"], cwd=kit, capture_output=True, text=True, timeout=900)
    print(f"--- ./workbook exam --list: exit {r.returncode}, {time.monotonic() - started:.1f} s\n"
          f"{r.stderr[-2000:]}{r.stdout[:300]}", flush=True)
    check(r.returncode == 0 and re.search(r"^vectors\s", r.stdout, re.M) is not None,
          f"exam: ./workbook exam --list lists the question kinds, exit {r.returncode}")
    allowed = needed_for(kit, "exam_practice", "exam/exam_practice") | \
        {"build.ninja", os.path.join(kit, "build", "student", "CMakeFiles", "cmake.verify_globs")}
    extra = sorted(built_outputs(kit) - before - allowed)
    check(not extra, f"exam: only the exam program and what it needs were built ({extra[:5]})")


def case_hang(kit, ex):
    """Exercise 1.1 never returns: its tests time out once, and no picture is rendered."""
    e = next(x for x in ex if x.id == "1.1")
    path = os.path.join(kit, e.path)
    with open(path, encoding="utf-8") as f:
        stub = f.read()
    loop = stub.replace('throw NotImplemented("1.1");', "for (volatile int spin = 0;; spin = spin + 0) {\n    }", 1)
    check(loop != stub, "hang: exercise 1.1's stub is replaced by a loop")
    with open(path, "w", encoding="utf-8") as f:
        f.write(loop)
    try:
        rc, out = run_check(kit, "1.1")
    finally:
        with open(path, "w", encoding="utf-8") as f:
            f.write(stub)
    check(rc == 1 and "timed out" in row(out, "1.1"), f"hang: 1.1 timed out ({row(out, '1.1')})")
    check(out.count("timed out:") == 1, "hang: one verdict, once")
    check("[check] rendering" not in out and "its picture is not rendered" in out,
          "hang: no picture is rendered for it, and check says so")


def case_hints(kit, ex):
    """Each mistake's own hint, though it fails other catalogued cases first."""
    with open(os.path.join(ROOT, "tests", "hints", "mistakes.json"), encoding="utf-8") as f:
        hints = json.load(f)
    for exercise_id, patch, case in HINT_CASES:
        e = next(x for x in ex if x.id == exercise_id)
        path = os.path.join(kit, e.path)
        with open(path, encoding="utf-8") as f:
            stub = f.read()
        solve(kit, e)
        if os.path.isfile(patch):
            case = read_mutant(patch).caught_by
        else:
            with tempfile.NamedTemporaryFile("w", suffix=".patch", dir=kit, delete=False) as f:
                f.write(patch)
            patch = f.name
        r = git_apply(kit, patch)
        check(r.returncode == 0, f"hint {exercise_id}: the mistake applies to the kit ({r.stderr.strip()})")
        try:
            rc, out = run_check(kit, exercise_id, "--hint", "--no-pictures")
        finally:
            with open(path, "w", encoding="utf-8") as f:
                f.write(stub)
            if patch.startswith(kit):
                os.remove(patch)
        want = hints[case]["hint"]
        check(rc == 1 and f'failing test case: "{case}"' in out and f"hint (this mistake): {want}" in out,
              f"hint {exercise_id}: the case and hint of the mistake made: {case!r}")


def case_correct(kit, exercise):
    solve(kit, exercise)
    rc, out = run_check(kit, exercise.id)
    check(rc == 0 and "passed" in row(out, exercise.id), f"correct {exercise.id}: check {exercise.id} passes")
    pic = os.path.join(kit, "out", "check", f"{exercise.id}.png")
    size, count, marks_them = marked(pic) if os.path.isfile(pic) else (None, -1, False)
    check(size is not None and size[0] > 3 * WIDTH and size[1] > HEIGHT and count == 0 and marks_them,
          f"correct {exercise.id}: out/check/{exercise.id}.png has no pixel marked (size {size}, {count} differ)")


def case_wrong(kit, exercise):
    mutant = read_mutant(MISTAKE)
    r = git_apply(kit, MISTAKE)
    check(r.returncode == 0, f"wrong {exercise.id}: the mistake applies to the kit ({r.stderr.strip()})")
    rc, out = run_check(kit, exercise.id, "--hint")
    check(rc == 1 and "failed" in row(out, exercise.id), f"wrong {exercise.id}: check {exercise.id} fails, exit {rc}")
    check(f'failing test case: "{mutant.caught_by}"' in out,
          f"wrong {exercise.id}: the failing case named is the mistake's: {mutant.caught_by!r}")
    check("the check " in out and "failed at tests/" in out, f"wrong {exercise.id}: the failing check and its line")
    check("hint (this mistake): " in out, f"wrong {exercise.id}: --hint gives the mistake's own hint")
    m = re.search(r"(\d+) of (\d+) pixels differ from the reference", out)
    said = int(m.group(1)) if m else 0
    pic = os.path.join(kit, "out", "check", f"{exercise.id}.png")
    size, count, marks_them = marked(pic) if os.path.isfile(pic) else (None, -1, False)
    check(said > 0 and count == said and marks_them,
          f"wrong {exercise.id}: out/check/{exercise.id}.png marks the extra pixels ({count} differ in its panels, "
          f"{said} said, each marked: {marks_them})")


def case_watch(kit, exercise, correct_text, poll):
    """--watch with the mistake in place: saving the correct file starts a new run within
    WATCH_LIMIT seconds, which passes."""
    how = "polling" if poll else "inotifywait" if shutil.which("inotifywait") else "polling (no inotifywait)"
    # The module itself: ./workbook would first install inotify-tools when missing and root.
    cmd = [sys.executable, "-m", "tools.check", exercise.id, "--watch", "--no-pictures"] + (["--poll"] if poll else [])
    p = subprocess.Popen(cmd, cwd=kit, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                         start_new_session=True)
    lines = []
    cond = threading.Condition()

    def reader():
        for line in p.stdout:
            with cond:
                lines.append((time.monotonic(), line.rstrip("\n")))
                cond.notify_all()

    def wait_for(pattern, after, timeout):
        deadline = time.monotonic() + timeout
        with cond:
            while True:
                for t, line in lines[after:]:
                    if re.search(pattern, line):
                        return t, lines.index((t, line))
                left = deadline - time.monotonic()
                if left <= 0 or p.poll() is not None and not any(re.search(pattern, l) for _, l in lines[after:]):
                    return None, len(lines)
                cond.wait(min(left, 0.2))

    threading.Thread(target=reader, daemon=True).start()
    try:
        t, i = wait_for(r"^\[check\] watching steps/", 0, 600)
        first = "\n".join(l for _, l in lines[:i])
        check(t is not None and "failed" in row(first, exercise.id), f"watch ({how}): the first run shows {exercise.id} failing")
        time.sleep(1.3)  # a save a moment after the run (not in step with a 0.5 s poll)
        saved = time.monotonic()
        with open(os.path.join(kit, exercise.path), "w", encoding="utf-8") as f:
            f.write(correct_text)
        t, j = wait_for(r"changed: checking again", i, 30)
        delay = (t - saved) if t is not None else None
        check(delay is not None and delay <= WATCH_LIMIT,
              f"watch ({how}): the save starts a new run within {WATCH_LIMIT:g} s "
              f"({'none' if delay is None else f'{delay:.2f} s'})")
        t2, k = wait_for(r"^\[check\] watching steps/", j, 600)
        second = "\n".join(l for _, l in lines[j:k])
        check(t2 is not None and "passed" in row(second, exercise.id),
              f"watch ({how}): the new run checks the saved code: {exercise.id} passes")
    finally:
        os.killpg(p.pid, signal.SIGKILL)
        p.wait()
        print("\n".join(l for _, l in lines[-40:]), flush=True)


def main():
    if len(sys.argv) not in (2, 3):
        print(__doc__, file=sys.stderr)
        return 2
    work = os.path.abspath(sys.argv[1])
    build = os.path.abspath(sys.argv[2]) if len(sys.argv) == 3 else os.path.join(ROOT, "build", "release")
    started = time.monotonic()
    kit = os.path.join(work, "kit")
    shutil.rmtree(kit, ignore_errors=True)
    os.makedirs(work, exist_ok=True)
    write_kit(kit, ROOT)
    # This build's step 01 program, built when it is not (ctest runs after the build).
    program = pictures.program(ROOT, build, 1)[0]
    render_references(kit, ROOT, steps={1}, build=build, log=print,
                      build_programs=not os.path.exists(program))
    print(f"kit written with step 01's reference pictures: {time.monotonic() - started:.1f} s", flush=True)
    ex = exercises(ROOT)
    exercise = next(e for e in ex if e.id == EXERCISE)
    case_fresh(kit, ex)
    case_exam(kit)
    case_hang(kit, ex)
    case_correct(kit, exercise)
    with open(os.path.join(kit, exercise.path), encoding="utf-8") as f:
        correct_text = f.read()
    case_wrong(kit, exercise)
    case_hints(kit, ex)
    case_watch(kit, exercise, correct_text, poll=False)
    if shutil.which("inotifywait"):
        git_apply(kit, MISTAKE)
        case_watch(kit, exercise, correct_text, poll=True)
    print(f"{time.monotonic() - started:.1f} s in all", flush=True)
    print(f"{len(failures)} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
