"""Building a step's worker in the grading tree and running its exercise cases: the
configure, the build of the student's code behind the judge's call server (judge_worker_NN:
no test in it), the reason a build fails, each case as a fresh checker and a fresh worker
(tools/grading/judge), and a step's rows for the report."""
import os
import re
import stat
import sys
from dataclasses import dataclass

from .box import clean_env, sandboxed, write_private
from .errors import GradeError
from .exercises import MAX_RESULT_BYTES
from .grade_report import exercise_row, printable, say
from . import judge
from .grading_tree import read


# The grading build's optimization: -O1, not Release's -O3. A student's grade is mostly the
# compile of their step sources, which -O1 makes about a third faster; the tests' cases run
# well within their limits at -O1 (CI runs them under the sanitizers too), and the points are
# the same (no -ffast-math either way, so the same IEEE arithmetic).
GRADING_FLAGS = "-O1 -DNDEBUG"


# How the grading tree is configured: BOXES_GRADING (no ctest discovery, which would run the
# student's code in the build), no step programs (the grader runs only exercise suites) and
# so no window (no SDL2, Dear ImGui or OpenGL to install where it grades).
GRADING_CACHE = {"CMAKE_BUILD_TYPE": "Release", "CMAKE_CXX_FLAGS_RELEASE": GRADING_FLAGS,
                 "BOXES_GRADING": "ON", "BOXES_TESTS_BUILD_PROGRAMS": "OFF", "BOXES_WINDOW": "OFF"}


def configure(work, iso):
    """Configures the grading tree once (sandboxed like the builds: it reads the reference's
    CMake files, but writes only WORK/build); exits with the reason when that fails. Then
    regenerates the build files if the CMake files changed, so no build needs to."""
    build = os.path.join(work, "build")
    cache_file = os.path.join(build, "CMakeCache.txt")
    cache = read(cache_file).splitlines() if os.path.exists(cache_file) else []
    configured = {line.split("=", 1)[0].split(":")[0]: line.split("=", 1)[1] for line in cache
                  if "=" in line and not line.startswith(("//", "#"))}
    fresh = os.path.exists(os.path.join(build, "build.ninja")) and all(
        configured.get(k) == v for k, v in GRADING_CACHE.items())
    os.makedirs(build, exist_ok=True)
    if not fresh:
        say("configuring the grading tree (once; later grades reuse it)", iso.log)
        r = sandboxed(["cmake", "-S", os.path.join(work, "src"), "-B", build, "-G", "Ninja"] +
                      [f"-D{k}={v}" for k, v in GRADING_CACHE.items()], iso.build, iso,
                      writable=[build], env=clean_env(build), readable=[os.path.join(work, "src")])
    else:
        r = sandboxed(["cmake", "--build", build, "--target", "build.ninja"], iso.build, iso,
                      writable=[build], env=clean_env(build), readable=[os.path.join(work, "src")])
    if not r.ok:
        (iso.log or sys.stderr).write((r.stdout + r.stderr).decode(errors="replace"))
        raise GradeError(f"grade: configuring the grading tree failed ({r.reason}; see above)")


def cmake_build(work, targets, iso):
    """Builds targets (names, or object files by their path in WORK/build) in the sandbox: the
    compilers run on the student's sources, so the build writes only WORK/build, within the
    build limits (as another user than the grader's, WORK/build is that user's only while
    it builds: sandbox.run lends it, so no test can change what later builds use)."""
    build = os.path.join(work, "build")
    return sandboxed(["cmake", "--build", build, "--target", *targets, "--", f"-j{iso.jobs}"],
                     iso.build, iso, writable=[build], env=clean_env(build),
                     readable=[os.path.join(work, "src")])


def build_step(work, number, iso):
    """'' when the step's worker builds (judge_worker_NN: the student's step sources, those of
    the steps it links and the judge's call server; no test, hidden or not), else the reason
    it does not ('does not compile: ...')."""
    src = os.path.join(work, "src")
    r = cmake_build(work, [f"judge_worker_{number}"], iso)
    if r.ok:
        return ""
    output = (r.stdout + r.stderr).decode(errors="replace")
    write_private(os.path.join(work, f"build-step{number}.log"), output + f"\n[grade] build result: {r.reason}\n")
    return build_reason(r, output, src)


def build_reason(result, output, src):
    """'does not compile: ...' for a failed build: a limit it hit (with the source being
    compiled then), or the compiler's first error."""
    if result.status in ("time limit", "memory limit", "output limit", "crashed"):
        compiling = re.findall(r" -c (\S+\.(?:cpp|cc|cxx))\b", output)
        where = f" (compiling {compiling[-1].replace(src + '/', '')})" if compiling else ""
        if result.status == "time limit":
            where += f" (the build ran over {result.seconds:.0f} s)"
        elif result.status == "output limit":
            error = first_error(output, src)
            where += f": {error}" if error != "the build failed" else ""
        return f"does not compile: {result.reason}{where}"
    return f"does not compile: {first_error(output, src)}"


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


@dataclass
class CaseOutcome:
    name: str
    status: str  # passed | failed | time limit | memory limit | output limit | crashed
    reason: str  # "" when passed, else e.g. "crashed: SIGSEGV" or "failed: <assertion>"
    seconds: float
    hidden: bool = False  # one of the instructor's hidden tests

    @property
    def passed(self):
        return self.status == "passed"


def doctest_filter(name):
    """doctest splits a filter at commas: a comma inside a name is escaped."""
    return name.replace(",", "\\,")


def read_result(path):
    """The bytes of a test's result file, or None. The folder was the student code's: a link
    there is not followed (the grader may read what the student may not), nor a FIFO."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return None
    with os.fdopen(fd, "rb") as f:
        info = os.fstat(f.fileno())
        if not stat.S_ISREG(info.st_mode) or info.st_size > MAX_RESULT_BYTES:
            return None
        return f.read(MAX_RESULT_BYTES + 1)


def build_and_run_visible(work, number, items, iso, runner, checker, log):
    """The first half of a step: its worker's build, then its visible cases (a fresh checker
    and worker each, judge.run_case). Returns (build error, {exercise: [CaseOutcome]})."""
    error = build_step(work, number, iso)
    outcomes = {e.id: [] for e in items}
    if not error:
        error = judge.probe(runner, os.path.join(work, "build", f"judge_worker_{number}"), f"{number}-probe")
        if error:
            say(printable(f"step {number}: {error[1]}"), log)
    if not error:
        run_cases(work, number, [c for c in checker.cases if not c.hidden], runner, checker, outcomes, log)
    return error, outcomes


def run_hidden(work, number, runner, checker, error, outcomes, log):
    """The second half: the step's hidden cases, once every step's visible cases have run,
    so that no worker of a visible case ever runs after a worker that saw a hidden input."""
    if not error:
        run_cases(work, number, [c for c in checker.cases if c.hidden], runner, checker, outcomes, log)


def run_cases(work, number, cases, runner, checker, outcomes, log):
    if not cases:
        return
    worker = os.path.join(work, "build", f"judge_worker_{number}")
    hidden = cases[0].hidden
    say(f"step {number}: running {len(cases)} {'hidden' if hidden else 'visible'} test cases", log)
    for case in cases:
        outcomes.setdefault(case.exercise, [])
        i = checker.cases.index(case)
        status, reason, seconds = judge.run_case(runner, checker, case, worker, f"{number}-{i}")
        o = CaseOutcome(case.name, status, reason, seconds, case.hidden)
        if not o.passed:
            say(printable(f"step {number}: {'(hidden) ' if hidden else ''}{case.name}: {o.reason}"), log)
        outcomes[case.exercise].append(o)


def step_rows(number, items, checker, error, outcomes, notes, seconds):
    """The rows of one step's exercises, from its build and its cases' outcomes."""
    for ex in outcomes:
        if ex not in {e.id for e in items}:
            notes.append(f"suite 'exercise {ex}' has no exercise marker: not counted")
    hidden = {}
    for case in checker.cases:
        hidden[case.exercise] = hidden.get(case.exercise, 0) + case.hidden
    return [exercise_row(e, number, error, outcomes.get(e.id, []), seconds, hidden.get(e.id, 0))
            for e in items]
