"""Grades a student's tree against the workbook's reference tests.

usage: ./workbook grade STUDENT_TREE [--hidden DIR] [--junit FILE] [--json FILE] [--timeout S]
                        [--memory MB] [--output MB] [--build-timeout S] [--build-memory MB]
                        [--steps 01,02] [--work DIR] [--jobs N] [--no-isolation]
       (python3 -m tools.grading.grade ..., from the repository root; in-process: grade())

What the student owns: the C++ sources and headers in the step folders (steps/NN_name/*.cpp,
*.hpp, ...). Everything else comes from this reference tree: core/, tests/, the CMake files,
data/. The grading tree is assembled in WORK/src (default build/grade/src): the reference's
files, the step sources of the starter kit (so a file the student deleted is a stub, never
the reference solution), then the student's step sources over them. An instructor's hidden
tests (--hidden DIR) are doctest files named stepNN*.cpp; their cases of a suite "exercise
N.M", in whatever doctest form, count for exercise N.M.

The judge (tools/grading/judge) runs every test case as a checker (the reference's tests
and every expected value, built once for every student in WORK/judge: no student code, no
student file compiled) and a worker (the student's functions behind a call server, no test
at all), joined by pipes: the worker answers calls, the checker decides. Hidden tests are
only ever in the judge's folder, in a checker of their own that runs the hidden cases only,
after every visible case. Each step's worker is built on its own, so a step that does not
compile scores zero for its exercises (with the compiler's first error) and the other steps
are still graded. An exercise earns its points (from the reference's markers) when it has
test cases and all of them pass.

The student's code is untrusted: the configure, every build (the compilers read the
student's sources) and every test case run in sandbox.py's sandbox (bubblewrap: the
system read-only, one writable folder: WORK/build for a build, a fresh folder per test
case; a private /tmp, no network, no capabilities) with limits on wall-clock and CPU time,
memory (address space) and output (--timeout, --memory, --output per test case;
--build-timeout, --build-memory per step's build). Where bubblewrap cannot create
namespaces the grader says so and refuses, unless --no-isolation. The checker writes its
results to a file of its own, so what the student's code prints only counts against the
output limit.
A failing exercise says why: time limit, memory limit, output limit, crashed: SIGNAME,
failed: <first failing assertion>, does not compile: <first error or the limit it hit>.
The points table goes to the terminal, a JUnit XML file to --junit (default WORK/grade.xml;
the reason is each failure's message), and with --json FILE the same results per exercise
as JSON (exercise, title, step, points, max, status, reason, case, seconds).
WORK/build is kept between runs, so grading the next tree rebuilds only what changed. The
test cases run in folders under WORK that go when grading ends: nothing is left in /tmp.
The student's tree is read, never followed: regular files only, within the submission
reader's limits; a link, device or FIFO in its steps/ is left out and a note says why.
When the grading machine fails (its disk full), nothing is graded: the exit status is 75
and the message says why; grade again once that is fixed.
"""
import argparse
import dataclasses
import errno
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import traceback
from dataclasses import dataclass

from . import ROOT, sandbox
from . import judge
from .box import Isolation, check_user_access, disk_trouble, refuse_without_isolation
from .build_and_run import GRADING_CACHE, build_and_run_visible, configure, run_hidden, step_rows
from .errors import NOT_GRADED_EXIT, GradeError, NotGraded, OutOfTime
from .exercises import BEGIN, exercises, step_sources
from .grade_report import print_table, printable, results_by_exercise, say, write_json, write_junit
from .grading_tree import assemble, hidden_sources, share_tree
from .strict_numbers import MAX_JOBS, MAX_MB, MAX_SECONDS, decimal, integer, step_list
from .users import grading_user


@dataclass
class GradeOptions:
    """What grading one tree takes besides the tree: the command line's options, with its
    defaults (main() fills it from the command line; the class grader and Gradescope build
    it themselves)."""
    hidden: str = None  # folder of hidden doctest files stepNN*.cpp
    junit: str = None  # the JUnit XML file (None: WORK/grade.xml)
    json: str = None  # the per-exercise JSON file (None: none)
    timeout: float = 60.0  # CPU seconds of one test case's worker (judge.case_limits: wall 3x)
    memory: int = 2048  # MB of address space of a test process
    output: float = 16.0  # MB printed, and of any file a test writes
    build_timeout: float = 900.0  # seconds of one step's build
    build_memory: int = 4096  # MB of address space of a compiler or linker process
    steps: list = None  # e.g. ["01", "03"] (None: every step with exercises)
    work: str = None  # the grading tree and its build (None: build/grade)
    jobs: int = 2  # parallel compile jobs
    no_isolation: bool = False  # without bubblewrap (the limits still hold)
    user: str = None  # without bubblewrap, as root: the unprivileged user student code runs as
    private: tuple = ()  # more paths that user must not read (the class grader's results)
    judge: str = None  # the checkers' folder (None: WORK/judge); graders of one class share one


@dataclass
class Graded:
    """One tree's grade: the table's rows (exercise_row), the notes, the points."""
    rows: list
    notes: list
    earned: int
    total: int
    junit: str  # where the JUnit XML went


def solution_files(root=ROOT):
    """The step sources (and headers) of `root` that hold a solution block, relative to it."""
    found = []
    for path in step_sources(root):
        with open(path, encoding="utf-8", errors="replace") as f:
            if any(BEGIN.match(line) for line in f):
                found.append(os.path.relpath(path, root))
    return found


def scrub_solution_outputs(work, log=None):
    """After grading the reference: removes from WORK/build what was compiled from its
    solutions (the objects of sources that hold a solution block or include a header that
    does, and the libraries and test programs that contain them), so that no student graded
    next in this folder can read them. Their own build compiles those again anyway; the
    core, the tests and the other sources stay built."""
    build = os.path.join(work, "build")
    src = os.path.join(work, "src")
    solved = {os.path.normpath(os.path.join(src, rel)) for rel in solution_files()}
    ninja = shutil.which("ninja") or shutil.which("ninja-build")
    r = subprocess.run([ninja or "ninja", "-C", build, "-t", "deps"], capture_output=True, text=True)
    if r.returncode != 0:
        say(f"cannot list the build's dependencies ({r.stderr.strip()[:200]}): removing every object "
            "of the steps' sources and the tests", log)
    doomed, target = set(), None
    for line in r.stdout.splitlines():
        if line and not line.startswith(" "):
            target = line.split(":", 1)[0]
        elif line.strip() and target:
            if os.path.normpath(os.path.join(build, line.strip())) in solved:
                doomed.add(target)
    for d, _, files in os.walk(build):
        for n in files:
            path = os.path.join(d, n)
            rel = os.path.relpath(path, build)
            whole_step = r.returncode != 0 and rel.startswith(("steps/", "tests/")) and n.endswith(".o")
            program = ((rel.startswith("tests/test_step") and os.sep not in rel[len("tests/"):])
                       or (n.startswith("judge_worker_") and os.sep not in rel))
            if rel in doomed or whole_step or n.endswith(".a") or program:
                os.remove(path)


def grade(student, opts, out=None, log=None, deadline=None, partial=False):
    """Grades the tree `student` with GradeOptions `opts`: the points table to `out`
    (default stdout), progress to `log` (default stderr), the JUnit XML (and the JSON) to
    their files. Raises GradeError when grading cannot start or go on, NotGraded when the
    grading machine fails (its disk full), OutOfTime once time.monotonic() passes
    `deadline` (with `partial`: the exercises not graded by then fail with that reason
    instead), sandbox.Stopped after sandbox.stop_all()."""
    started = time.monotonic()
    out = out or sys.stdout
    student_path = os.path.abspath(student)
    if not os.path.isdir(os.path.join(student_path, "steps")):
        raise GradeError(f"grade: {student} has no steps/ folder: is it a workbook tree?")
    work = os.path.abspath(opts.work or os.path.join(ROOT, "build", "grade"))
    all_ex = exercises(ROOT)
    numbers = sorted({f"{e.step:02d}" for e in all_ex})
    steps = list(opts.steps) if opts.steps else numbers
    unknown = [s for s in steps if s not in numbers]
    if unknown:
        raise GradeError(f"grade: --steps {','.join(unknown)}: no such step with exercises "
                         f"(steps: {','.join(numbers)})")
    refuse_without_isolation(opts, log)
    user = None
    if opts.no_isolation and opts.user:
        if os.geteuid() != 0:
            raise GradeError("grade: --user runs student code as another user: that needs root", 2)
        try:
            user = grading_user(opts.user)
        except ValueError as e:
            raise GradeError(f"grade: --user: {e}", 2) from None
    elif opts.no_isolation and os.geteuid() == 0:
        say("WARNING: as root without --user, student code runs as root", log)
    hidden = opts.hidden and os.path.abspath(opts.hidden)
    judge_folder = os.path.abspath(opts.judge or os.path.join(work, "judge"))
    unreadable = (ROOT, student_path, hidden, judge_folder, os.path.expanduser("~"), "/home", "/root")
    # A build's files: the largest the grading build makes is a few tens of MB; one file of
    # a student's build (a huge initialised array, say) stops there.
    iso = Isolation(not opts.no_isolation,
                    build=sandbox.Limits(opts.build_timeout, opts.build_memory, opts.output, file_mb=512),
                    test=sandbox.Limits(opts.timeout, opts.memory, opts.output), jobs=opts.jobs,
                    hidden=tuple(dict.fromkeys(p for p in unreadable if p)), deadline=deadline, log=log,
                    user=user, disk=work)
    try:
        return _grade(student_path, opts, out, log, partial, work, all_ex, steps, hidden, iso, started,
                      judge_folder)
    except OSError as e:
        if e.errno in (errno.ENOSPC, errno.EDQUOT):
            raise NotGraded(f"the grading disk is full ({e.strerror}: {printable(str(e.filename))})") from e
        raise


def _grade(student_path, opts, out, log, partial, work, all_ex, steps, hidden, iso, started, judge_folder):
    os.makedirs(os.path.join(work, "build"), exist_ok=True)
    trouble = disk_trouble(work)
    if trouble:
        raise NotGraded(trouble)
    # The checkers: the reference's tests and the hidden ones, built once for every tree
    # graded here (or in a folder graders share), outside any sandbox: no student file in them.
    numbers = sorted({f"{e.step:02d}" for e in all_ex})
    hidden_by_step = hidden_sources(hidden, set(numbers), steps)
    try:
        checkers = judge.prepare(ROOT, judge_folder, hidden_by_step, steps, GRADING_CACHE, opts.jobs,
                                 timeout=max(opts.build_timeout, 3600.0), say=lambda t: say(t, log))
    except judge.JudgeError as e:
        raise GradeError(f"grade: {e}") from None
    workers, cmake = judge.worker_files(ROOT, steps)
    notes = assemble(student_path, work, workers, cmake)
    notes += [f"hidden tests for step {n}: {', '.join(name for name, _ in files)}"
              for n, files in sorted(hidden_by_step.items())]
    if os.geteuid() == 0:  # student code runs as another user (iso.user, or the sandbox's own)
        os.chmod(os.path.join(work, "build"), 0o755)
        share_tree(os.path.join(work, "src"))
    if iso.drop:
        os.chmod(work, 0o755)
        solutions = [os.path.join(ROOT, rel) for rel in solution_files()[:1]]
        check_user_access(iso, work, solutions + [hidden, judge_folder] + list(opts.private))
        notes.append(f"student code ran without isolation, as user {iso.user.name}")
    elif not iso.isolate:
        notes.append("student code ran without isolation (--no-isolation)")
    graded = {}  # step: [build error, {exercise: [CaseOutcome]}, seconds]
    done = set()  # the steps whose every case ran
    late = None  # when out of time (with `partial`): where
    try:
        configure(work, iso)
    except OutOfTime:
        if not partial:
            raise
        late, steps_to_run = "while configuring", []
    else:
        steps_to_run = steps
    # The cases' folders: the workers' in WORK (the clone's build/ by default), not the shared
    # /tmp; the checkers' in the judge folder, out of every sandbox's sight; both removed when
    # grading ends, however it ends.
    with tempfile.TemporaryDirectory(prefix="scratch-", dir=work, ignore_cleanup_errors=True) as scratch, \
            tempfile.TemporaryDirectory(prefix="cases-", dir=judge_folder, ignore_cleanup_errors=True) as private:
        if iso.drop:
            os.chmod(scratch, 0o711)  # the user reaches its case folders, lists nothing
        runner = judge.Runner(iso, scratch, private,
                              worker_readable=[os.path.join(work, "build"), os.path.join(work, "src", "data")],
                              judge_folder=judge_folder)
        try:
            # Every step's visible cases first, then the hidden ones: no worker of a visible
            # case runs after one that saw a hidden case's input.
            for number in steps_to_run:
                items = [e for e in all_ex if f"{e.step:02d}" == number]
                say(f"step {number}: building judge_worker_{number} (the student's code)", log)
                t0 = time.monotonic()
                error, outcomes = build_and_run_visible(work, number, items, iso, runner, checkers[number], log)
                graded[number] = [error, outcomes, time.monotonic() - t0]
                if not any(c.hidden for c in checkers[number].cases):
                    done.add(number)
            for number in steps_to_run:
                if number in done:
                    continue
                error, outcomes, _ = graded[number]
                t0 = time.monotonic()
                run_hidden(work, number, runner, checkers[number], error, outcomes, log)
                graded[number][2] += time.monotonic() - t0
                done.add(number)
        except OutOfTime:
            if not partial:
                raise
            late = "while running the cases"
    if late:
        say(f"out of time {late}: the exercises of step{'s' if len(steps) - len(done) > 1 else ''} "
            f"{', '.join(n for n in steps if n not in done)} are not graded", log)
    rows = []
    why = ("time limit", "not graded: the grading ran past its overall time limit")
    for number in steps:
        items = [e for e in all_ex if f"{e.step:02d}" == number]
        if number in done:
            error, outcomes, seconds = graded[number]
            rows += step_rows(number, items, checkers[number], error, outcomes, notes, seconds)
        else:
            rows += step_rows(number, items, checkers[number], why, {}, notes, 0.0)
    notes = [printable(n) for n in notes]
    if student_path == ROOT:
        scrub_solution_outputs(work, log)
    earned, total = print_table(rows, notes, out)
    junit = opts.junit or os.path.join(work, "grade.xml")
    write_junit(junit, rows, notes, time.monotonic() - started)
    if opts.json:
        write_json(opts.json, rows, notes, time.monotonic() - started)
    say(f"{earned} of {total} points; JUnit XML: {junit}", log)
    return Graded(rows, notes, earned, total, junit)


@dataclass
class Report:
    """One tree graded into a folder by grade_into."""
    code: int  # 0 graded; else the exit status ./workbook grade would have; None: out of time
    seconds: float
    results: list  # results_by_exercise (empty unless code is 0)
    notes: list
    last_line: str  # the log's last line (why, when code is not 0)


def grade_into(folder, tree, opts, limit=None, partial=False):
    """Grades `tree` in-process into `folder`, as the class grader and Gradescope keep a
    grade: points.txt (the table), grade.log (the progress), grade.xml and grade.json. A
    failure to grade is a Report with its code and the log's last line, not an exception;
    `limit`: seconds for the whole grading (OutOfTime: code None; with `partial`, the
    exercises not graded in time fail instead; NotGraded: code NOT_GRADED_EXIT, the last
    line "not graded: why"). sandbox.Stopped passes."""
    os.makedirs(folder, exist_ok=True)
    opts = dataclasses.replace(opts, junit=os.path.join(folder, "grade.xml"),
                               json=os.path.join(folder, "grade.json"))
    for f in (opts.junit, opts.json):
        if os.path.exists(f):
            os.remove(f)
    started = time.monotonic()
    deadline = started + limit if limit else None
    code, graded = 0, None
    with open(os.path.join(folder, "points.txt"), "w") as out, \
            open(os.path.join(folder, "grade.log"), "w") as log:
        try:
            graded = grade(tree, opts, out, log, deadline, partial)
        except OutOfTime:
            code = None
        except NotGraded as e:  # the machine's failure: the last line says why
            code = NOT_GRADED_EXIT
            log.write(f"not graded: {e}\n")
        except (GradeError, SystemExit) as e:
            code = e.code if isinstance(e.code, int) else 1
            if str(e):
                log.write(f"{e}\n")
        except Exception:  # a bug of the grader: its trace for the instructor, the class goes on
            code = 1
            log.write(traceback.format_exc())
    with open(os.path.join(folder, "grade.log"), errors="replace") as f:
        last = (f.read().strip().splitlines() or [""])[-1]
    if graded is None:
        return Report(code, time.monotonic() - started, [], [], last)
    return Report(0, time.monotonic() - started, results_by_exercise(graded.rows), graded.notes, last)


def _interrupted(signum, frame):
    raise KeyboardInterrupt


def main(argv):
    defaults = GradeOptions()
    p = argparse.ArgumentParser(prog="./workbook grade", description=__doc__.split("\n\n")[0],
                                epilog="\n\n".join(__doc__.split("\n\n")[2:]),
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("student", help="the student's workbook tree (a starter kit with their work)")
    p.add_argument("--hidden", help="folder of extra doctest files stepNN*.cpp")
    p.add_argument("--junit", help="JUnit XML file to write (default WORK/grade.xml)")
    p.add_argument("--json", help="also write the per-exercise results as JSON to this file")
    p.add_argument("--timeout", type=decimal(0, MAX_SECONDS), default=defaults.timeout,
                   help="time limit of one test case in seconds: CPU time of the student's code, "
                        "three times that on the wall clock (default %(default)g)")
    p.add_argument("--memory", type=integer(1, MAX_MB), default=defaults.memory,
                   help="memory limit of a test process in MB, address space (default %(default)d)")
    p.add_argument("--output", type=decimal(0, MAX_MB), default=defaults.output,
                   help="output limit in MB: what a test or a build prints, and any file a test "
                        "writes (default %(default)g)")
    p.add_argument("--build-timeout", type=decimal(0, MAX_SECONDS), default=defaults.build_timeout,
                   help="time limit of one step's build in seconds (default %(default)g; the first "
                        "build compiles the core too)")
    p.add_argument("--build-memory", type=integer(1, MAX_MB), default=defaults.build_memory,
                   help="memory limit of each compiler or linker process in MB (default %(default)d)")
    p.add_argument("--steps", type=step_list, help="grade only these steps, e.g. 01,03")
    p.add_argument("--work", help="where the grading tree and its build live (default build/grade)")
    p.add_argument("--jobs", type=integer(1, MAX_JOBS), default=defaults.jobs, help="parallel compile jobs (default %(default)d)")
    p.add_argument("--no-isolation", "--no-sandbox", dest="no_isolation", action="store_true",
                   help="build and run student code WITHOUT bubblewrap (the limits still hold); "
                        "only for code you trust, where bubblewrap cannot run")
    p.add_argument("--user", help="with --no-isolation, as root: build and run student code as this "
                                  "unprivileged user, which must not be able to read this tree; every "
                                  "process of it is killed after each command")
    args = p.parse_args(argv)
    opts = GradeOptions(**{f.name: getattr(args, f.name) for f in dataclasses.fields(GradeOptions)
                           if hasattr(args, f.name)})
    opts.steps = args.steps
    # SIGTERM as Ctrl-C: an exception, so the sandboxed command is killed and the scratch goes.
    signal.signal(signal.SIGTERM, _interrupted)
    try:
        grade(args.student, opts)
    except GradeError as e:
        print(printable(str(e)), file=sys.stderr)
        return e.code
    except NotGraded as e:
        print(f"grade: not graded: {e}; a failure of the grading machine, not of the student's code: "
              "grade again once it is fixed", file=sys.stderr)
        return NOT_GRADED_EXIT
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
