"""Gradescope: an autograder bundle that grades with the workbook's grader.

usage: ./workbook gradescope OUT.zip [--hidden DIR] [--steps 01,02] [--timeout S] [--limit S]
                           [--hidden-visibility after_published|hidden|after_due_date]
                           [--user NAME]
       (python3 -m tools.grading.gradescope bundle OUT.zip ..., from the repository root)
       python3 -m tools.grading.gradescope prime [--root DIR]   (setup.sh, in the bundle)
       python3 -m tools.grading.gradescope run [--root DIR]     (run_autograder, in the bundle)

The bundle (upload it as the assignment's autograder, on Gradescope's Ubuntu 22.04 base
image; 24.04 works too) holds setup.sh, run_autograder, workbook/ (this reference tree:
tests, core, CMake files, solutions) and the instructor's hidden tests. setup.sh installs
the packages the grading build needs with workbook/tools/deps.sh (group grade), creates the
unprivileged user that builds and runs the students' code where bubblewrap cannot run (in
Docker, Gradescope's case, its namespaces are refused), and primes the grading build in
/autograder/work by grading the reference once, so a submission costs only the compile of
its step sources. run_autograder grades /autograder/submission (the student's upload: the
workbook tree, its steps/ folder, or one archive of it) with grade.py (in-process) and
writes /autograder/results/results.json, on every path: one test per exercise (name,
number, score, max_score, status passed/failed, output: every test case and the first
failure, visibility), the total score and the grader's notes, as plain text; when the
grader itself fails or runs out of its overall time limit (--limit, below Gradescope's
timeout), a clear message and zero points. An exercise with hidden test cases is shown
with --hidden-visibility (default after_published), and a visible companion test of 0
points reports only its public test cases; the top-level output counts only the exercises
without hidden tests.

Without bubblewrap, run as root: the student's code is compiled and run as the user of
--user (default boxes-student; BOXES_GRADING_USER overrides it), which cannot read the
bundle (the solutions, the hidden tests) nor write the results; every process of it is
killed after each command. AUTOGRADER_ROOT (default /autograder) moves the whole layout,
to try the bundle locally; BOXES_GRADE_WORK moves the grading build.
"""
import argparse
import json
import os
import re
import stat
import sys
import tempfile
import time
import traceback
import zipfile

from . import ROOT, sandbox
from .strict_numbers import MAX_SECONDS, decimal, step_list
from .cgroups import usable_cpus
from .errors import NOT_GRADED_EXIT
from .exercises import exercises
from .grade_class import run_grader
from .grade_report import one_line
from .kit import tracked_files
from .submissions import ARCHIVE_SUFFIXES, SubmissionError, read_submission, stage

VISIBILITIES = ("hidden", "after_due_date", "after_published", "visible")  # Gradescope's

# Gradescope's own timeout is 10 minutes unless the assignment sets more (at most 40): the
# grader stops before it, so that results.json always holds what was graded.
DEFAULT_LIMIT = 540.0
DEFAULT_USER = "boxes-student"

SETUP_SH = """#!/usr/bin/env bash
# Gradescope runs this once, as root, when it builds the autograder image (its Ubuntu 22.04
# base image; 24.04 works too). Written by the workbook's tools/grading/gradescope.py.
set -euo pipefail
source_dir=$(cd "$(dirname "$0")" && pwd)  # /autograder/source
root=$(cd "${AUTOGRADER_ROOT:-/autograder}" && pwd)
export DEBIAN_FRONTEND=noninteractive
if [[ -z ${BOXES_SKIP_APT:-} ]]; then
  apt-get update
  "$source_dir/workbook/tools/deps.sh" grade
fi
# Where bubblewrap cannot run (Docker's seccomp profile refuses its namespaces), the
# students' code is built and run as this unprivileged user.
user=${BOXES_GRADING_USER:-@USER@}
if ! id -u "$user" >/dev/null 2>&1; then
  useradd --system --no-create-home --home-dir /nonexistent --shell /usr/sbin/nologin "$user"
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
results=$root/results/results.json
mkdir -p "$root/results"
: >"$results"  # a builtin: emptied even where nothing else runs
(cd "$root/source/workbook" && python3 -m tools.grading.gradescope run --root "$root")
status=$?
# The grader writes results.json on every path it sees; this covers the ones it cannot
# (it did not start, or was killed).
if [[ ! -s $results ]]; then
  printf '{"score": 0, "output_format": "text", "tests": [], "output": "%s (exit %s). %s"}\\n' \\
    "The autograder failed before it could grade this submission" "$status" \\
    "This is not a verdict on your code: your instructor sees the autograder's log." >"$results"
fi
exit 0
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
    steps = args.steps or numbers
    if any(s not in numbers for s in steps):
        raise SystemExit(f"gradescope: --steps {','.join(steps)}: steps are {','.join(numbers)}")
    if args.timeout >= args.limit:
        raise SystemExit(f"gradescope: --timeout {args.timeout:g} must be below --limit {args.limit:g}")
    config = {"steps": steps, "timeout": args.timeout, "limit": args.limit, "user": args.user,
              "hidden_visibility": args.hidden_visibility, "hidden_cases": {}}
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
        add(z, "setup.sh", SETUP_SH.replace("@USER@", args.user), True)
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
    print(f"[gradescope] upload it as the assignment's autograder (base image Ubuntu 22.04), with "
          f"Gradescope's timeout above {args.limit:g} s; students submit their workbook tree (or a "
          "zip of it)", file=sys.stderr)
    return 0


# In the autograder image -----------------------------------------------------------------


def layout(root):
    source = os.path.join(root, "source")
    with open(os.path.join(source, "config.json")) as f:
        config = json.load(f)
    hidden = os.path.join(source, "hidden")
    work = os.environ.get("BOXES_GRADE_WORK") or os.path.join(root, "work")
    return config, (hidden if os.path.isdir(hidden) else None), work


def student_user(config, isolated):
    """The user the students' code runs as: none with bubblewrap or when the grader is not
    root (then it is the grader's own user, as on a lab machine)."""
    if isolated or os.geteuid() != 0:
        return None
    return os.environ.get("BOXES_GRADING_USER") or config.get("user") or DEFAULT_USER


def isolation(log=sys.stderr):
    """True where bubblewrap isolates here (the probe runs the sandbox's own command line);
    else says why, once."""
    problem = sandbox.isolation_problem()
    if problem:
        print(f"[gradescope] {problem}: the students' code runs without bubblewrap", file=log)
    return problem is None


def lock_down(root):
    """What the students' user must not read or write: the bundle (the solutions, the hidden
    tests, the grader), the upload and the results; the grading folder is the grader's."""
    for name, mode in (("source", 0o700), ("submission", 0o700), ("results", 0o755)):
        path = os.path.join(root, name)
        if os.path.isdir(path) and os.geteuid() == os.stat(path).st_uid:
            os.chmod(path, mode)


def prime(args):
    config, hidden, work = layout(args.root)
    lock_down(args.root)
    isolated = isolation()
    user = student_user(config, isolated)
    report = os.path.join(work, "reference")
    r = run_grader(ROOT, work, report, config["steps"], hidden, config["timeout"],
                   usable_cpus(), not isolated, user=user)
    os.chmod(report, 0o700)
    rows = r.results
    missing = [x["exercise"] for x in rows if not x["passed"]]
    with open(os.path.join(report, "points.txt")) as f:
        sys.stdout.write(f.read())
    if r.code != 0 or not rows or missing:
        print(f"[gradescope] the reference does not get full points ({', '.join(missing) or r.last_line}): "
              f"see {report}", file=sys.stderr)
        return 1
    how = "in bubblewrap" if isolated else (f"as user {user}" if user else "without isolation")
    print(f"[gradescope] grading build primed in {r.seconds:.0f} s ({usable_cpus()} CPUs, "
          f"student code {how}): the reference gets full points", file=sys.stderr)
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


WHEN = {"after_published": "once the grades are published", "after_due_date": "after the due date",
        "hidden": "when your instructor shows them"}


def results_json(rows, config, notes, seconds):
    """Gradescope's results.json for the graded rows. Every text is plain text (it holds
    what the student's code printed and the names of their files). With hidden tests the
    top-level output, which students always see, counts only the exercises without any."""
    visibility = config.get("hidden_visibility", "after_published")
    tests = []
    if config.get("hidden_cases") or any(r.get("hidden", 0) for r in rows):
        # Which hidden test files and suites there are is not for them either.
        notes = [n for n in notes if not n.startswith(("hidden tests", "suite '"))]

    def has_hidden(r):  # the grader's own list of the checker's cases: whatever doctest form
        return r.get("hidden", 0) > 0

    for r in rows:
        lines = [f"{r['points']} of {r['max']} points: {'passed' if r['passed'] else r['status']}"]
        if not r["passed"] and r["reason"]:
            lines.append(f"first failure: {r['reason']}")
        lines += r["details"]
        tests.append({"name": f"exercise {r['exercise']}: {r['title']}", "number": r["exercise"],
                      "score": r["points"], "max_score": r["max"],
                      "status": "passed" if r["passed"] else "failed", "output": "\n".join(lines),
                      "visibility": visibility if has_hidden(r) else "visible"})
        if has_hidden(r):
            public = r.get("public_details", [])
            tests.append({"name": f"exercise {r['exercise']}: public tests", "number": f"{r['exercise']}.0",
                          "score": 0, "max_score": 0,
                          "status": "passed" if r.get("public_passed") else "failed",
                          "output": "\n".join(public) or "no public test cases", "visibility": "visible"})
    shown = [r for r in rows if not has_hidden(r)]
    steps = ", ".join(config["steps"])
    if len(shown) < len(rows):
        held = [r["exercise"] for r in rows if has_hidden(r)]
        head = (f"{sum(r['points'] for r in shown)} of {sum(r['max'] for r in shown)} points from the "
                f"exercises without hidden tests (steps {steps}). Exercises {', '.join(held)} also have "
                f"hidden tests: their points show {WHEN.get(visibility, 'later')}.")
    else:
        head = (f"{sum(r['points'] for r in rows)} of {sum(r['max'] for r in rows)} points (steps {steps}).")
    return {"score": sum(r["points"] for r in rows), "execution_time": round(seconds),
            "stdout_visibility": "hidden", "output_format": "text", "test_output_format": "text",
            "test_name_format": "text",
            "output": head + " Each exercise earns its points when all its test cases pass.\n"
                      + "".join(f"note: {n}\n" for n in notes),
            "tests": tests}


def failure(message):
    """results.json when there is no grade: zero points and why, never an empty page."""
    return {"score": 0, "output": message, "output_format": "text", "stdout_visibility": "hidden",
            "tests": []}


GRADER_FAILED = ("The autograder could not grade this submission: a problem of the autograder, "
                 "not a verdict on your code. Your instructor sees its log; submit again or ask them.")


def run(args):
    """run_autograder: grades the submission; results.json on every path."""
    started = time.monotonic()
    results_dir = os.path.join(args.root, "results")

    def write(doc):
        os.makedirs(results_dir, exist_ok=True)
        tmp = os.path.join(results_dir, ".results.json.tmp")
        with open(tmp, "w") as f:
            json.dump(doc, f, indent=1)
            f.write("\n")
        os.chmod(tmp, 0o644)
        os.replace(tmp, os.path.join(results_dir, "results.json"))

    try:
        return grade_submission(args, started, write)
    except BaseException as e:  # the grader's own failure (a bug, an interrupt): still a page
        traceback.print_exc()
        write(failure(GRADER_FAILED))
        print(f"[gradescope] the grader failed: {type(e).__name__}: {e}", file=sys.stderr)
        return 1


def grade_submission(args, started, write):
    config, hidden, work = layout(args.root)
    lock_down(args.root)
    try:
        files = submission_files(os.path.join(args.root, "submission"))
    except (SubmissionError, OSError) as e:
        write(failure(f"The submission cannot be graded: {one_line(e)}. Submit your workbook tree (the "
                      "folder with steps/) or a zip of it."))
        print(f"[gradescope] not graded: {one_line(e)}", file=sys.stderr)
        return 0
    limit = float(config.get("limit", DEFAULT_LIMIT))
    with tempfile.TemporaryDirectory(prefix="boxes-submission-") as tmp:
        tree = stage(files, os.path.join(tmp, "tree"))
        report = os.path.join(tmp, "report")
        isolated = isolation()
        graded = run_grader(tree, work, report, config["steps"], hidden, config["timeout"],
                            usable_cpus(), not isolated, user=student_user(config, isolated),
                            limit=max(1.0, limit - (time.monotonic() - started)), partial=True)
        with open(os.path.join(report, "points.txt"), errors="replace") as f:
            table = f.read()
        with open(os.path.join(report, "grade.log"), errors="replace") as f:
            log = f.read()
    sys.stdout.write(table)
    sys.stderr.write(log)
    if graded.code is None:
        write(failure(f"The grading ran past its time limit of {limit:g} s before any exercise was "
                      "graded: zero points. Your instructor sees its log."))
        return 0
    if graded.code == NOT_GRADED_EXIT:
        write(failure(f"Not graded: {graded.last_line[len('not graded: '):]}. A problem of the "
                      "autograder's machine, not a verdict on your code: submit again."))
        print(f"[gradescope] {graded.last_line}", file=sys.stderr)
        return 0
    if graded.code != 0:
        write(failure(GRADER_FAILED))
        print(f"[gradescope] the grader failed: {graded.last_line}", file=sys.stderr)
        return 0
    rows = graded.results
    notes = list(graded.notes)
    if config.get("hidden_cases") or hidden:  # which hidden test files and suites there are is not for them
        notes = [n for n in notes if not n.startswith(("hidden tests", "suite '"))]
    if not isolated:
        notes.append("the tests ran in Gradescope's container without bubblewrap")
    write(results_json(rows, config, notes, time.monotonic() - started))
    print(f"[gradescope] {sum(r['points'] for r in rows)} of {sum(r['max'] for r in rows)} points: "
          f"{os.path.join(args.root, 'results', 'results.json')}", file=sys.stderr)
    return 0


def main(argv):
    p = argparse.ArgumentParser(prog="./workbook gradescope", description=__doc__.split("\n\n")[0],
                                epilog="\n\n".join(__doc__.split("\n\n")[2:]),
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    b = sub.add_parser("bundle", help="write the autograder zip")
    b.add_argument("out", help="the zip to write, e.g. autograder.zip")
    b.add_argument("--hidden", help="folder of extra doctest files stepNN*.cpp")
    b.add_argument("--steps", type=step_list, help="grade only these steps, e.g. 01,02 (default all)")
    b.add_argument("--timeout", type=decimal(0, MAX_SECONDS), default=60.0, help="seconds per test case (default 60)")
    b.add_argument("--limit", type=decimal(0, MAX_SECONDS), default=DEFAULT_LIMIT,
                   help="seconds for the whole grading of a submission, below the assignment's "
                        "Gradescope timeout (default %(default)g: Gradescope's default is 10 minutes)")
    b.add_argument("--user", default=DEFAULT_USER,
                   help="the unprivileged user setup.sh creates to run students' code without "
                        "bubblewrap (default %(default)s)")
    b.add_argument("--hidden-visibility", choices=VISIBILITIES[:3], default="after_published",
                   help="when students see the exercises with hidden tests (default after_published)")
    root = os.environ.get("AUTOGRADER_ROOT", "/autograder")
    for name in ("prime", "run"):
        s = sub.add_parser(name)
        s.add_argument("--root", default=root, help="the Gradescope layout (default $AUTOGRADER_ROOT or /autograder)")
    args = p.parse_args(argv)
    return {"bundle": bundle, "prime": prime, "run": run}[args.command](args)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
