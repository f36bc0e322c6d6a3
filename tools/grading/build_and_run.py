"""Building a step's test program in the grading tree and running its exercise cases: the
configure, the build (the step's hidden tests first, on their own), the reason a build
fails, the list of cases, each case in its own sandboxed process and how it ended, and a
step's rows for the report."""
import os
import re
import shutil
import stat
import sys
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass

from . import ROOT
from .box import clean_env, sandboxed, write_private
from .errors import GradeError
from .exercises import MAX_RESULT_BYTES, case_results, step_dirs
from .grade_report import exercise_row, printable, say
from .grading_tree import HIDDEN_DIR, hidden_copies, read, set_hidden_mode


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
    regenerates the build files if the CMake files changed (hidden tests added, say), so no
    build needs to: CMake takes a source it cannot read for a missing one, and the hidden
    tests are readable only now (CMake reads no file of the student's) and while they
    compile."""
    build = os.path.join(work, "build")
    cache_file = os.path.join(build, "CMakeCache.txt")
    cache = read(cache_file).splitlines() if os.path.exists(cache_file) else []
    configured = {line.split("=", 1)[0].split(":")[0]: line.split("=", 1)[1] for line in cache
                  if "=" in line and not line.startswith(("//", "#"))}
    fresh = os.path.exists(os.path.join(build, "build.ninja")) and all(
        configured.get(k) == v for k, v in GRADING_CACHE.items())
    os.makedirs(build, exist_ok=True)
    set_hidden_mode(work, 0o644)
    try:
        if not fresh:
            say("configuring the grading tree (once; later grades reuse it)", iso.log)
            r = sandboxed(["cmake", "-S", os.path.join(work, "src"), "-B", build, "-G", "Ninja"] +
                          [f"-D{k}={v}" for k, v in GRADING_CACHE.items()], iso.build, iso,
                          writable=[build], env=clean_env(build), readable=[os.path.join(work, "src")])
        else:
            r = sandboxed(["cmake", "--build", build, "--target", "build.ninja"], iso.build, iso,
                          writable=[build], env=clean_env(build), readable=[os.path.join(work, "src")])
    finally:
        set_hidden_mode(work, 0)
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
    """'' when test_stepNN builds, else the reason it does not ('does not compile: ...').

    The step's hidden tests compile first, on their own: only then may they be read, and what
    the compiler says of them (the student's headers can make it quote them) goes to the
    instructor's log, never into the reason. The rest of the build cannot read them."""
    src = os.path.join(work, "src")
    name = next(os.path.basename(d) for d in step_dirs(ROOT) if os.path.basename(d).startswith(number))
    hidden_failed = None
    copies = hidden_copies(work, number)
    if copies:
        set_hidden_mode(work, 0o644, number)
        try:
            r = cmake_build(work, [f"tests/CMakeFiles/test_step{number}.dir/{HIDDEN_DIR[6:]}/"
                                   f"{os.path.basename(c)}.o" for c in copies], iso)
        finally:
            set_hidden_mode(work, 0, number)
        if not r.ok:
            write_private(os.path.join(work, f"build-step{number}-hidden.log"),
                          (r.stdout + r.stderr).decode(errors="replace") + f"\n[grade] build result: {r.reason}\n")
            hidden_failed = r
    # Without the hidden tests' objects test_stepNN cannot link: then the student's own
    # sources and the public tests, whose errors the student may see.
    targets = ([f"step{name}", f"tests/CMakeFiles/test_step{number}.dir/step{name}.cpp.o"]
               if hidden_failed else [f"test_step{number}"])
    r = cmake_build(work, targets, iso)
    if r.ok and not hidden_failed:
        return ""
    if r.ok:
        return (f"does not compile: step {number}'s hidden tests do not compile with these sources "
                f"({hidden_failed.reason}; the compiler's messages are for the instructor)")
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


def test_readable(binary):
    """What a test program reads: its build tree (WORK/build) and the data (WORK/src/data)."""
    build = os.path.dirname(os.path.dirname(binary))
    return [build, os.path.join(os.path.dirname(build), "src", "data")]


def list_cases(binary, iso, folder):
    """[(suite, test case)] of a test program, or raises RuntimeError saying why not."""
    os.makedirs(folder, exist_ok=True)
    if iso.drop:
        os.chown(folder, iso.user.uid, iso.user.gid)
    limits = iso.test
    r = sandboxed([binary, "--list-test-cases", "--reporters=xml"], limits, iso, scratch=folder,
                  env=clean_env(folder), keep=int(limits.output_mb * (1 << 20)),
                  readable=test_readable(binary))
    return listed_cases(r)


def listed_cases(r):
    """[(suite, test case)] from the sandbox result of --list-test-cases --reporters=xml, or
    raises RuntimeError(status, reason) when its output is no such list."""
    try:
        root = ET.fromstring(r.stdout.decode(errors="replace"))
    except ET.ParseError as e:
        # Before any test runs: the student's code in a global object's constructor, say.
        status = r.status if r.status not in ("ok", "failed") else "failed"
        reason = r.reason if status != "failed" else f"failed: {r.reason}"
        raise RuntimeError(status, f"{reason} (the test program does not list its tests)") from e
    return [(c.get("testsuite", ""), c.get("name", "")) for c in root.iter("TestCase")]


@dataclass
class CaseOutcome:
    name: str
    status: str  # passed | failed | time limit | memory limit | output limit | crashed
    reason: str  # "" when passed, else e.g. "crashed: SIGSEGV" or "failed: <assertion>"
    seconds: float

    @property
    def passed(self):
        return self.status == "passed"


def doctest_filter(name):
    """doctest splits a filter at commas: a comma inside a name is escaped."""
    return name.replace(",", "\\,")


def run_case(binary, suite, name, iso, folder):
    """One test case in its own sandboxed process, in a fresh writable folder (isolated: a
    tmpfs of the test's disk limit, so no test fills the grading disk), with the test
    limits. doctest writes its results to a file there (the one file that reaches the
    host), so what the student's code prints is only counted against the output limit,
    never read as a result."""
    os.makedirs(folder)
    if iso.drop:
        os.chown(folder, iso.user.uid, iso.user.gid)
    result = os.path.join(folder, "result.xml")
    cmd = [binary, "--test-suite=" + doctest_filter(suite), "--test-case=" + doctest_filter(name),
           "--reporters=xml", "--no-version", f"--out={result}"]
    try:
        r = sandboxed(cmd, iso.test, iso, scratch=folder, outputs=[result], env=clean_env(folder),
                      keep=1 << 16, readable=test_readable(binary))
        data = read_result(result)
        found = [c for c in case_results(data) if c.name == name] if data else []
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return case_outcome(name, r, found)


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


def case_outcome(name, r, found):
    """How one test case ended, from its sandbox result r and the results doctest wrote for
    it (found: the CaseResults named `name`; [] when it wrote none)."""
    if r.status in ("time limit", "memory limit", "output limit", "crashed"):
        return CaseOutcome(name, r.status, r.reason, r.seconds)
    if found and found[0].passed and r.ok:
        return CaseOutcome(name, "passed", "", r.seconds)
    if found and not found[0].passed:
        message = found[0].message
        if "bad_alloc" in message:  # doctest caught the refused allocation
            return CaseOutcome(name, "memory limit", "memory limit", r.seconds)
        return CaseOutcome(name, "failed", f"failed: {message or 'the test case failed'}", r.seconds)
    if found:  # passed, but the process then failed (at exit: the student's code still ran)
        return CaseOutcome(name, "failed", f"failed: the test passed, then the program ended with "
                           f"{r.reason}", r.seconds)
    last = (r.stderr.decode(errors="replace").strip().splitlines() or [""])[-1][:200]
    why = "no test result (it ended before doctest wrote one)" if r.ok else f"no test result, {r.reason[8:]}"
    return CaseOutcome(name, "failed", f"failed: {why}" + (f": {last}" if last else ""), r.seconds)


def grade_step(work, number, items, iso, scratch, notes, log, t0):
    """The rows of one step's exercises: its build, then each exercise case on its own."""
    error = build_step(work, number, iso)
    outcomes = {e.id: [] for e in items}
    if not error:
        binary = os.path.join(work, "build", "tests", f"test_step{number}")
        try:
            cases = [(s, n) for s, n in list_cases(binary, iso, os.path.join(scratch, "list"))
                     if s.startswith("exercise ")]
        except RuntimeError as e:
            error, cases = tuple(e.args), []
        say(f"step {number}: running {len(cases)} test cases", log)
        for i, (suite, name) in enumerate(cases):
            ex = suite.split(" ", 1)[1]
            if ex not in outcomes:
                notes.append(f"suite '{suite}' has no exercise marker: not counted")
                outcomes[ex] = []
            o = run_case(binary, suite, name, iso, os.path.join(scratch, f"{number}-{i}"))
            if not o.passed:
                say(printable(f"step {number}: {name}: {o.reason}"), log)
            outcomes[ex].append(o)
    return [exercise_row(e, number, error, outcomes[e.id], time.monotonic() - t0) for e in items]
