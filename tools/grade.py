#!/usr/bin/python3
"""Grades a student's tree against the workbook's reference tests.

usage: tools/grade.py STUDENT_TREE [--hidden DIR] [--junit FILE] [--json FILE] [--timeout S]
                      [--steps 01,02] [--work DIR] [--jobs N]
       (./workbook grade ...)

What the student owns: the C++ sources and headers in the step folders (steps/NN_name/*.cpp,
*.hpp, ...). Everything else comes from this reference tree: core/, tests/, the CMake files,
data/. The grading tree is assembled in WORK/src (default build/grade/src): the reference's
files, the step sources of the starter kit (so a file the student deleted is a stub, never
the reference solution), then the student's step sources over them. An instructor's hidden
tests (--hidden DIR) are doctest files named stepNN*.cpp; each is compiled into that step's
test program (test_stepNN) and its TEST_SUITE("exercise N.M") cases count for exercise N.M.

Each step's test program is built on its own, so a step that does not compile scores zero
for its exercises (with the compiler's first error) and the other steps are still graded. Each
test case of an "exercise N.M" suite runs as its own process with a time limit; an exercise
earns its points (from the reference's markers) when it has test cases and all of them pass.
The tests run under bubblewrap where it works (the files read-only but a private /tmp, no
network) and write their results to a file, so what the student's code prints is not read.
The points table goes to the terminal, a JUnit XML file to --junit (default WORK/grade.xml),
and with --json FILE the same results per exercise as JSON (exercise, points, max, status,
reason, seconds).
WORK/build is kept between runs, so grading the next tree rebuilds only what changed.
"""
import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from exercises import SOURCE_SUFFIXES, case_results, exercises, step_dirs  # noqa: E402
from kit import strip_solutions, tracked_files  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def say(text):
    print(f"[grade] {text}", file=sys.stderr, flush=True)


def read(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return f.read()


# The grading tree ---------------------------------------------------------------------------


def student_sources(student, step_names):
    """{relative path: text} of the student's sources in the reference's step folders."""
    owned = {}
    for name in step_names:
        base = os.path.join(student, "steps", name)
        for d, _, files in os.walk(base):
            for f in files:
                if f.endswith(SOURCE_SUFFIXES):
                    path = os.path.join(d, f)
                    owned[os.path.relpath(path, student)] = read(path)
    return owned


def hidden_tests(hidden, step_numbers):
    """{step number: [file names]} of an instructor's hidden test files (stepNN*.cpp)."""
    by_step = {}
    if not hidden:
        return by_step
    if not os.path.isdir(hidden):
        raise SystemExit(f"grade: --hidden {hidden}: no such folder")
    for f in sorted(os.listdir(hidden)):
        m = re.match(r"(?:test_)?step(\d\d)", f)
        if not f.endswith(".cpp"):
            continue
        if not m or m.group(1) not in step_numbers:
            raise SystemExit(f"grade: hidden test {f}: name it stepNN*.cpp for one of the steps "
                             f"{', '.join(sorted(step_numbers))}")
        by_step.setdefault(m.group(1), []).append(f)
    return by_step


def sync_tree(dest, files):
    """Makes dest hold exactly `files` ({relative path: bytes}); unchanged files keep their
    time stamps, so the build dir rebuilds only what changed."""
    for rel, data in files.items():
        path = os.path.join(dest, rel)
        try:
            with open(path, "rb") as f:
                if f.read() == data:
                    continue
        except OSError:
            pass
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as f:
            f.write(data)
    wanted = {os.path.normpath(r) for r in files}
    for d, _, names in os.walk(dest, topdown=False):
        for n in names:
            rel = os.path.normpath(os.path.relpath(os.path.join(d, n), dest))
            if rel not in wanted:
                os.remove(os.path.join(d, n))
        if d != dest and not os.listdir(d):
            os.rmdir(d)


def assemble(student, hidden, work, steps):
    """Writes the grading tree into work/src; returns the notes for the report."""
    notes = []
    step_names = [os.path.basename(d) for d in step_dirs(ROOT)]
    files = {}
    for rel in tracked_files(ROOT):
        path = os.path.join(ROOT, rel)
        if rel.startswith("steps/") and rel.endswith(SOURCE_SUFFIXES):
            text, _ = strip_solutions(read(path), path, ROOT)  # the kit's stub
            files[rel] = text.encode()
        else:
            with open(path, "rb") as f:
                files[rel] = f.read()
    owned = student_sources(student, step_names)
    if not owned:
        notes.append(f"no step sources found under {student}/steps: every exercise is a stub")
    for rel, text in owned.items():
        if rel not in files and rel.endswith((".cpp", ".cc")):
            notes.append(f"{rel} is new: it is not built (the reference CMake files list the sources)")
        files[rel] = text.encode()
    # Hidden tests: compiled into their step's test program.
    by_step = hidden_tests(hidden, {n[:2] for n in step_names})
    extra = ["", "# Added by tools/grade.py: the instructor's hidden tests."]
    for number, names in by_step.items():
        if number not in steps:
            continue
        for n in names:
            with open(os.path.join(hidden, n), "rb") as f:
                files[f"tests/hidden/{n}"] = f.read()
        sources = " ".join(f"hidden/{n}" for n in names)
        extra.append(f"if(TARGET test_step{number})\n    target_sources(test_step{number} PRIVATE {sources})\nendif()")
        notes.append(f"hidden tests for step {number}: {', '.join(names)}")
    if len(extra) > 2:
        files["tests/CMakeLists.txt"] += ("\n".join(extra) + "\n").encode()
    sync_tree(os.path.join(work, "src"), files)
    return notes


# Building and running ------------------------------------------------------------------------


def configure(work):
    build = os.path.join(work, "build")
    if os.path.exists(os.path.join(build, "build.ninja")):
        return
    say("configuring the grading tree (once; later grades reuse it)")
    r = subprocess.run(["cmake", "-S", os.path.join(work, "src"), "-B", build, "-G", "Ninja",
                        "-DCMAKE_BUILD_TYPE=Release"], capture_output=True, text=True)
    if r.returncode != 0:
        sys.stderr.write(r.stdout + r.stderr)
        raise SystemExit("grade: configuring the grading tree failed (see above)")


def first_error(output, src):
    """The compiler's (or linker's) first error, one line, paths relative to the tree."""
    for pattern in (r": (fatal )?error:", r"undefined reference|ld returned", r"\berror\b"):
        for line in output.splitlines():
            if re.search(pattern, line) and not line.startswith(("ninja:", "FAILED:")):
                line = line.replace(src + "/", "")
                return " ".join(line.split())[:400]
    for line in output.splitlines():
        if line.startswith("FAILED:"):
            return line[:400]
    return "the build failed"


def build_step(work, number, jobs):
    """(ok, first error) for test_stepNN."""
    r = subprocess.run(["cmake", "--build", os.path.join(work, "build"), "--target",
                        f"test_step{number}", "--", f"-j{jobs}"], capture_output=True, text=True)
    if r.returncode == 0:
        return True, ""
    with open(os.path.join(work, f"build-step{number}.log"), "w") as f:
        f.write(r.stdout + r.stderr)
    return False, first_error(r.stdout + r.stderr, os.path.join(work, "src"))


def list_cases(binary, sandbox):
    """[(suite, test case)] of a test program, or raises RuntimeError saying why not."""
    try:
        r = subprocess.run(list(sandbox) + [binary, "--list-test-cases", "--reporters=xml"],
                           capture_output=True, text=True, timeout=60)
        root = ET.fromstring(r.stdout)
    except (OSError, subprocess.TimeoutExpired, ET.ParseError) as e:
        raise RuntimeError(f"the test program does not list its tests ({type(e).__name__})") from e
    return [(c.get("testsuite", ""), c.get("name", "")) for c in root.iter("TestCase")]


def sandbox_prefix(cwd, work):
    """bubblewrap around the student's code where it works: the file system read-only but
    for a private /tmp and the working folder, no network. [] when it is not available."""
    bwrap = shutil.which("bwrap")
    if not bwrap:
        return []
    prefix = [bwrap, "--ro-bind", "/", "/", "--dev", "/dev", "--proc", "/proc", "--tmpfs", "/tmp",
              "--ro-bind", work, work, "--bind", cwd, cwd, "--unshare-net", "--unshare-pid", "--die-with-parent"]
    try:
        ok = subprocess.run(prefix + ["true"], capture_output=True, timeout=30).returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        ok = False
    return prefix if ok else []


def run_case(binary, suite, name, timeout, cwd, sandbox=()):
    """(passed, message) for one test case, in its own process with a time limit."""
    # The results go to a file, not stdout, so what the student's code prints is not read.
    result = os.path.join(cwd, f"result-{os.getpid()}-{time.monotonic_ns()}.xml")
    cmd = list(sandbox) + [binary, f"--test-suite={suite}", f"--test-case={name}",
                           "--reporters=xml", "--no-version", f"--out={result}"]
    try:
        p = subprocess.Popen(cmd, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             stdin=subprocess.DEVNULL, text=True, start_new_session=True)
        _, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        return False, f"timed out after {timeout:g} s"
    if p.returncode < 0:
        return False, f"crashed ({signal.Signals(-p.returncode).name})"
    results = [r for r in case_results(result) if r.name == name] if os.path.exists(result) else []
    if os.path.exists(result):
        os.remove(result)
    if not results:
        last = (err.strip().splitlines() or [""])[-1][:200]
        return False, f"no result (exit code {p.returncode}) {last}".strip()
    return results[0].passed, results[0].message


# The report ----------------------------------------------------------------------------------


def print_table(rows, notes, out=sys.stdout):
    total = sum(r["points"] for r in rows)
    earned = sum(r["points"] for r in rows if r["passed"])
    out.write(f"\nGrade: {earned} of {total} points\n\n")
    out.write(f"{'exercise':<9} {'points':>6}  {'result':<7} first failure\n")
    for r in rows:
        got = r["points"] if r["passed"] else 0
        out.write(f"{r['id']:<9} {got:>2} / {r['points']:<2}  {'passed' if r['passed'] else 'FAILED':<7} "
                  f"{r['message']}\n")
    for n in notes:
        out.write(f"note: {n}\n")
    out.flush()
    return earned, total


def write_junit(path, rows, notes, seconds):
    failures = sum(1 for r in rows if not r["passed"])
    suites = ET.Element("testsuites", name="boxes grading", tests=str(len(rows)),
                        failures=str(failures), time=f"{seconds:.1f}")
    by_step = {}
    for r in rows:
        by_step.setdefault(r["step"], []).append(r)
    for step, items in sorted(by_step.items()):
        s = ET.SubElement(suites, "testsuite", name=f"step {step}", tests=str(len(items)),
                          failures=str(sum(1 for r in items if not r["passed"])))
        props = ET.SubElement(s, "properties")
        ET.SubElement(props, "property", name="points",
                      value=str(sum(r["points"] for r in items if r["passed"])))
        ET.SubElement(props, "property", name="points_possible", value=str(sum(r["points"] for r in items)))
        for r in items:
            c = ET.SubElement(s, "testcase", classname=f"exercise {r['id']}",
                              name=f"exercise {r['id']}: {r['title']} ({r['points']} point{'s' if r['points'] != 1 else ''})",
                              time=f"{r['seconds']:.2f}")
            if not r["passed"]:
                f = ET.SubElement(c, "failure", message=r["message"], type="failed")
                f.text = "\n".join(r["details"]) or r["message"]
            else:
                ET.SubElement(c, "system-out").text = "\n".join(r["details"])
        earned = sum(r["points"] for r in items if r["passed"])
        ET.SubElement(s, "system-out").text = (
            f"step {step}: {earned} of {sum(r['points'] for r in items)} points\n" +
            "".join(f"note: {n}\n" for n in notes))
    ET.indent(suites)
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    ET.ElementTree(suites).write(path, encoding="utf-8", xml_declaration=True)


def write_json(path, rows, notes, seconds):
    """The per-exercise results as JSON, for batch grading and other tools: one object per
    exercise with its points earned (0 unless passed), max, status ("passed" or "failed"),
    reason (empty when passed) and seconds."""
    doc = {"points": sum(r["points"] for r in rows if r["passed"]),
           "max": sum(r["points"] for r in rows), "seconds": round(seconds, 2),
           "exercises": [{"exercise": r["id"], "title": r["title"], "step": r["step"],
                          "points": r["points"] if r["passed"] else 0, "max": r["points"],
                          "status": "passed" if r["passed"] else "failed",
                          "reason": "" if r["passed"] else r["message"],
                          "case": r.get("case", ""), "seconds": round(r["seconds"], 2)}
                         for r in rows],
           "notes": list(notes)}
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")


def grade(args):
    started = time.monotonic()
    student = os.path.abspath(args.student)
    if not os.path.isdir(os.path.join(student, "steps")):
        raise SystemExit(f"grade: {args.student} has no steps/ folder: is it a workbook tree?")
    work = os.path.abspath(args.work or os.path.join(ROOT, "build", "grade"))
    all_ex = exercises(ROOT)
    numbers = sorted({f"{e.step:02d}" for e in all_ex})
    steps = numbers if not args.steps else [s.zfill(2) for s in args.steps.split(",")]
    unknown = [s for s in steps if s not in numbers]
    if unknown:
        raise SystemExit(f"grade: --steps {','.join(unknown)}: no such step with exercises "
                         f"(steps: {','.join(numbers)})")
    notes = assemble(student, args.hidden and os.path.abspath(args.hidden), work, steps)
    configure(work)
    rows = []
    with tempfile.TemporaryDirectory(prefix="boxes-grade-") as cwd:
        sandbox = [] if args.no_sandbox else sandbox_prefix(cwd, work)
        if not sandbox:
            notes.append("tests ran without a sandbox" + ("" if args.no_sandbox else
                         " (bubblewrap is missing or cannot run here)"))
        for number in steps:
            items = [e for e in all_ex if f"{e.step:02d}" == number]
            say(f"step {number}: building test_step{number}")
            t0 = time.monotonic()
            ok, error = build_step(work, number, args.jobs)
            results = {e.id: [] for e in items}
            if ok:
                binary = os.path.join(work, "build", "tests", f"test_step{number}")
                try:
                    cases = [(s, n) for s, n in list_cases(binary, sandbox) if s.startswith("exercise ")]
                except RuntimeError as e:
                    ok, error, cases = False, str(e), []
                say(f"step {number}: running {len(cases)} test cases")
                for suite, name in cases:
                    ex = suite.split(" ", 1)[1]
                    if ex not in results:
                        notes.append(f"suite '{suite}' has no exercise marker: not counted")
                        results[ex] = []
                    c0 = time.monotonic()
                    passed, message = run_case(binary, suite, name, args.timeout, cwd, sandbox)
                    results[ex].append((name, passed, message, time.monotonic() - c0))
            for e in items:
                cases = results[e.id]
                failed = [c for c in cases if not c[1]]
                if not ok:
                    passed, message = False, f"step {number} does not build: {error}"
                    if error.startswith("the test program"):
                        message = f"step {number}: {error}"
                elif not cases:
                    passed, message = False, "no test cases for this exercise"
                else:
                    passed = not failed
                    message = "" if passed else f"{failed[0][0]}: {failed[0][2]}"
                details = [f"{'passed' if c[1] else 'FAILED'}: {c[0]}" + ("" if c[1] else f": {c[2]}")
                           for c in cases] or [message]
                seconds = sum(c[3] for c in cases) if cases else time.monotonic() - t0
                rows.append({"id": e.id, "title": e.title, "points": e.points, "step": number,
                             "passed": passed, "message": message, "details": details,
                             "seconds": seconds})
    earned, total = print_table(rows, notes)
    junit = args.junit or os.path.join(work, "grade.xml")
    write_junit(junit, rows, notes, time.monotonic() - started)
    if args.json:
        write_json(args.json, rows, notes, time.monotonic() - started)
    say(f"{earned} of {total} points; JUnit XML: {junit}")
    return 0


def main(argv):
    p = argparse.ArgumentParser(prog="./workbook grade", description=__doc__.split("\n\n")[0],
                                epilog="\n\n".join(__doc__.split("\n\n")[2:]),
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("student", help="the student's workbook tree (a starter kit with their work)")
    p.add_argument("--hidden", help="folder of extra doctest files stepNN*.cpp")
    p.add_argument("--junit", help="JUnit XML file to write (default WORK/grade.xml)")
    p.add_argument("--json", help="also write the per-exercise results as JSON to this file")
    p.add_argument("--timeout", type=float, default=60.0, help="seconds per test case (default 60)")
    p.add_argument("--steps", help="grade only these steps, e.g. 01,03")
    p.add_argument("--work", help="where the grading tree and its build live (default build/grade)")
    p.add_argument("--jobs", type=int, default=2, help="parallel compile jobs (default 2)")
    p.add_argument("--no-sandbox", action="store_true",
                   help="run the tests without bubblewrap (read-only files, no network)")
    args = p.parse_args(argv)
    if args.timeout <= 0:
        p.error("--timeout must be positive")
    return grade(args)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
