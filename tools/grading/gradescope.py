"""Gradescope: an autograder bundle that grades with the workbook's grader.

usage: ./workbook gradescope OUT.zip [--hidden DIR] [--steps 01,02] [--timeout S]
                           [--hidden-visibility after_published|hidden|after_due_date]
       (python3 -m tools.grading.gradescope bundle OUT.zip ..., from the repository root)
       python3 -m tools.grading.gradescope prime [--root DIR]   (setup.sh, in the bundle)
       python3 -m tools.grading.gradescope run [--root DIR]     (run_autograder, in the bundle)

The bundle (upload it as the assignment's autograder; Gradescope's Ubuntu 24.04 image has
the C++20 compiler the workbook needs) holds setup.sh, run_autograder, workbook/ (this
reference tree: tests, core, CMake files, solutions) and the instructor's hidden tests.
setup.sh installs the Debian/Ubuntu packages with workbook/tools/deps.sh (groups build,
grade) and primes the grading build in /autograder/work by grading the reference once, so
a submission costs only the compile of its step sources. run_autograder grades
/autograder/submission (the student's upload: the workbook tree, its steps/ folder, or one
archive of it) with grade.py (in-process) and writes /autograder/results/results.json: one test per
exercise (name, number, score, max_score, status passed/failed, output: every test case and
the first failure, visibility), the total score and the grader's notes. An exercise with
hidden test cases is shown with --hidden-visibility (default after_published), and a
visible companion test of 0 points reports only its public test cases.

AUTOGRADER_ROOT (default /autograder) moves the whole layout, to try the bundle locally;
BOXES_GRADE_WORK moves the grading build.
"""
import argparse
import json
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile
import time
import zipfile

from . import ROOT
from .exercises import exercises
from .grade_class import run_grader
from .kit import tracked_files
from .submissions import ARCHIVE_SUFFIXES, SubmissionError, read_submission, stage

VISIBILITIES = ("hidden", "after_due_date", "after_published", "visible")  # Gradescope's

SETUP_SH = """#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder image (Ubuntu).
# Written by the workbook's tools/grading/gradescope.py.
set -euo pipefail
source_dir=$(cd "$(dirname "$0")" && pwd)  # /autograder/source
root=$(cd "${AUTOGRADER_ROOT:-/autograder}" && pwd)
export DEBIAN_FRONTEND=noninteractive
if [[ -z ${BOXES_SKIP_APT:-} ]]; then
  apt-get update
  "$source_dir/workbook/tools/deps.sh" build grade
fi
# The workbook needs CMake 3.25 and a C++20 compiler: Gradescope's Ubuntu 24.04 image.
if ! cmake --version | awk 'NR == 1 { split($3, v, "."); exit !(v[1] > 3 || (v[1] == 3 && v[2] >= 25)) }'; then
  echo "setup.sh: CMake $(cmake --version | awk 'NR == 1 { print $3 }') is too old: choose the Ubuntu 24.04 base image" >&2
  exit 1
fi
# Grade the reference once: the core and the tests are built into the image, so a
# submission costs only the compile of its own step sources.
cd "$source_dir/workbook"
python3 -m tools.grading.gradescope prime --root "$root"
"""

RUN_AUTOGRADER = """#!/usr/bin/env bash
# Gradescope runs this for every submission (working directory /autograder); it writes
# /autograder/results/results.json. Written by the workbook's tools/grading/gradescope.py.
root=$(cd "${AUTOGRADER_ROOT:-/autograder}" && pwd)
cd "$root/source/workbook"
exec python3 -m tools.grading.gradescope run --root "$root"
"""


def hidden_case_names(hidden):
    """{exercise id: [test case names]} of the hidden doctest files."""
    found = {}
    for n in sorted(os.listdir(hidden)):
        if not n.endswith(".cpp"):
            continue
        with open(os.path.join(hidden, n), encoding="utf-8", errors="replace") as f:
            parts = re.split(r'TEST_SUITE\("', f.read())
        for p in parts[1:]:
            m = re.match(r"exercise (\d+\.\d+)\"", p)
            if m:
                found.setdefault(m.group(1), []).extend(re.findall(r'TEST_CASE\("([^"]*)"', p))
    return found


def bundle(args):
    numbers = sorted({f"{e.step:02d}" for e in exercises(ROOT)})
    steps = [s.zfill(2) for s in args.steps.split(",")] if args.steps else numbers
    if any(s not in numbers for s in steps):
        raise SystemExit(f"gradescope: --steps {args.steps}: steps are {','.join(numbers)}")
    config = {"steps": steps, "timeout": args.timeout, "hidden_visibility": args.hidden_visibility,
              "hidden_cases": {}}
    if args.hidden:
        if not os.path.isdir(args.hidden):
            raise SystemExit(f"gradescope: --hidden {args.hidden}: no such folder")
        config["hidden_cases"] = hidden_case_names(args.hidden)
    out = os.path.abspath(args.out)
    os.makedirs(os.path.dirname(out), exist_ok=True)

    def add(z, arcname, data, executable=False):
        info = zipfile.ZipInfo(arcname, date_time=(2024, 1, 1, 0, 0, 0))
        info.external_attr = ((0o755 if executable else 0o644) | stat.S_IFREG) << 16
        info.compress_type = zipfile.ZIP_DEFLATED
        z.writestr(info, data)

    count = 0
    with zipfile.ZipFile(out + ".tmp", "w") as z:
        add(z, "setup.sh", SETUP_SH, True)
        add(z, "run_autograder", RUN_AUTOGRADER, True)
        add(z, "config.json", json.dumps(config, indent=1) + "\n")
        for rel in tracked_files(ROOT):
            if rel.startswith(("slides/", "out/")):  # not needed to grade
                continue
            path = os.path.join(ROOT, rel)
            with open(path, "rb") as f:
                add(z, "workbook/" + rel, f.read(), os.access(path, os.X_OK))
            count += 1
        if args.hidden:
            for n in sorted(os.listdir(args.hidden)):
                if n.endswith(".cpp"):
                    with open(os.path.join(args.hidden, n), "rb") as f:
                        add(z, "hidden/" + n, f.read())
    os.replace(out + ".tmp", out)
    hidden = sum(len(v) for v in config["hidden_cases"].values())
    print(f"[gradescope] {out}: setup.sh, run_autograder, {count} workbook files, steps {','.join(steps)}"
          + (f", {hidden} hidden test cases ({args.hidden_visibility})" if hidden else ""), file=sys.stderr)
    print("[gradescope] upload it as the assignment's autograder (Ubuntu 24.04 image); students "
          "submit their workbook tree (or a zip of it)", file=sys.stderr)
    return 0


# In the autograder image -----------------------------------------------------------------


def layout(root):
    source = os.path.join(root, "source")
    with open(os.path.join(source, "config.json")) as f:
        config = json.load(f)
    hidden = os.path.join(source, "hidden")
    work = os.environ.get("BOXES_GRADE_WORK") or os.path.join(root, "work")
    return config, (hidden if os.path.isdir(hidden) else None), work


def isolation_works():
    """bubblewrap inside Gradescope's container usually cannot make namespaces; there the
    container itself (one per submission) is the sandbox."""
    bwrap = shutil.which("bwrap")
    if not bwrap:
        return False
    try:
        return subprocess.run([bwrap, "--ro-bind", "/", "/", "--unshare-all", "true"],
                              capture_output=True, timeout=30).returncode == 0
    except (OSError, subprocess.TimeoutExpired):
        return False


def prime(args):
    config, hidden, work = layout(args.root)
    report = os.path.join(work, "reference")
    r = run_grader(ROOT, work, report, config["steps"], hidden, config["timeout"],
                   os.cpu_count() or 1, not isolation_works())
    rows = r.results
    missing = [x["exercise"] for x in rows if not x["passed"]]
    with open(os.path.join(report, "points.txt")) as f:
        sys.stdout.write(f.read())
    if r.code != 0 or not rows or missing:
        print(f"[gradescope] the reference does not get full points ({', '.join(missing)}): see "
              f"{report}", file=sys.stderr)
        return 1
    print(f"[gradescope] grading build primed in {r.seconds:.0f} s: the reference gets full points",
          file=sys.stderr)
    return 0


def submission_files(folder):
    """The student's step sources: the upload as a tree, or the one archive in it."""
    try:
        return read_submission(folder)
    except SubmissionError as first:
        archives = [n for n in os.listdir(folder) if n.lower().endswith(ARCHIVE_SUFFIXES)]
        if len(archives) == 1:
            return read_submission(os.path.join(folder, archives[0]))
        raise first


def results_json(rows, config, notes, seconds):
    hidden_cases = config.get("hidden_cases", {})
    tests = []
    for r in rows:
        hidden_names = set(hidden_cases.get(r["exercise"], []))
        lines = [f"{r['points']} of {r['max']} points: {'passed' if r['passed'] else r['status']}"]
        if not r["passed"] and r["reason"]:
            lines.append(f"first failure: {r['reason']}")
        lines += r["details"]
        tests.append({"name": f"exercise {r['exercise']}: {r['title']}", "number": r["exercise"],
                      "score": r["points"], "max_score": r["max"],
                      "status": "passed" if r["passed"] else "failed", "output": "\n".join(lines),
                      "visibility": config.get("hidden_visibility", "after_published") if hidden_names else "visible"})
        if hidden_names:
            public = [d for d in r["details"] if not any(d.split(": ", 1)[-1].startswith(h) for h in hidden_names)]
            ok = all(d.startswith("passed") for d in public) and bool(public)
            tests.append({"name": f"exercise {r['exercise']}: public tests", "number": f"{r['exercise']}.0",
                          "score": 0, "max_score": 0, "status": "passed" if ok else "failed",
                          "output": "\n".join(public) or "no public test cases", "visibility": "visible"})
    total = sum(r["points"] for r in rows)
    maximum = sum(r["max"] for r in rows)
    return {"score": total, "execution_time": round(seconds), "stdout_visibility": "hidden",
            "output": f"{total} of {maximum} points (steps {', '.join(config['steps'])}); each exercise "
                      "earns its points when all its test cases pass.\n" + "".join(f"note: {n}\n" for n in notes),
            "tests": tests}


def run(args):
    started = time.monotonic()
    config, hidden, work = layout(args.root)
    results_dir = os.path.join(args.root, "results")
    os.makedirs(results_dir, exist_ok=True)

    def write(doc):
        with open(os.path.join(results_dir, "results.json"), "w") as f:
            json.dump(doc, f, indent=1)
            f.write("\n")

    try:
        files = submission_files(os.path.join(args.root, "submission"))
    except (SubmissionError, OSError) as e:
        write({"score": 0, "output": f"The submission cannot be graded: {e}. Submit your workbook "
                                     "tree (the folder with steps/) or a zip of it.", "tests": []})
        print(f"[gradescope] not graded: {e}", file=sys.stderr)
        return 0
    with tempfile.TemporaryDirectory(prefix="boxes-submission-") as tmp:
        tree = stage(files, os.path.join(tmp, "tree"))
        report = os.path.join(tmp, "report")
        isolated = isolation_works()
        graded = run_grader(tree, work, report, config["steps"], hidden, config["timeout"],
                            os.cpu_count() or 1, not isolated, limit=args.limit)
        with open(os.path.join(report, "points.txt")) as f:
            table = f.read()
        with open(os.path.join(report, "grade.log"), errors="replace") as f:
            log = f.read()
    sys.stdout.write(table)
    sys.stderr.write(log)
    if graded.code != 0:
        write({"score": 0, "output": "The grader failed (the instructor sees its log): "
               + graded.last_line[:300], "tests": []})
        return 0
    rows = graded.results
    # The students see the notes; which hidden test files there are is not for them.
    notes = [n for n in graded.notes if not n.startswith("hidden tests")]
    if not isolated:
        notes.append("the tests ran in Gradescope's container without bubblewrap")
    write(results_json(rows, config, notes, time.monotonic() - started))
    print(f"[gradescope] {sum(r['points'] for r in rows)} of {sum(r['max'] for r in rows)} points: "
          f"{results_dir}/results.json", file=sys.stderr)
    return 0


def main(argv):
    p = argparse.ArgumentParser(prog="./workbook gradescope", description=__doc__.split("\n\n")[0],
                                epilog="\n\n".join(__doc__.split("\n\n")[2:]),
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    b = sub.add_parser("bundle", help="write the autograder zip")
    b.add_argument("out", help="the zip to write, e.g. autograder.zip")
    b.add_argument("--hidden", help="folder of extra doctest files stepNN*.cpp")
    b.add_argument("--steps", help="grade only these steps, e.g. 01,02 (default all)")
    b.add_argument("--timeout", type=float, default=60.0, help="seconds per test case (default 60)")
    b.add_argument("--hidden-visibility", choices=VISIBILITIES[:3], default="after_published",
                   help="when students see the exercises with hidden tests (default after_published)")
    root = os.environ.get("AUTOGRADER_ROOT", "/autograder")
    for name in ("prime", "run"):
        s = sub.add_parser(name)
        s.add_argument("--root", default=root, help="the Gradescope layout (default $AUTOGRADER_ROOT or /autograder)")
        s.add_argument("--limit", type=float, default=None, help="seconds for the whole grading")
    args = p.parse_args(argv)
    return {"bundle": bundle, "prime": prime, "run": run}[args.command](args)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
