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
tests (--hidden DIR) are doctest files named stepNN*.cpp; each is compiled into that step's
test program (test_stepNN) and its TEST_SUITE("exercise N.M") cases count for exercise N.M.

Each step's test program is built on its own, so a step that does not compile scores zero
for its exercises (with the compiler's first error) and the other steps are still graded. Each
test case of an "exercise N.M" suite runs as its own process; an exercise earns its points
(from the reference's markers) when it has test cases and all of them pass.

The student's code is untrusted: the configure, every build (the compilers read the
student's sources) and every test case run in sandbox.py's sandbox (bubblewrap: the
system read-only, one writable folder: WORK/build for a build, a fresh folder per test
case; a private /tmp, no network, no capabilities) with limits on wall-clock and CPU time,
memory (address space) and output (--timeout, --memory, --output per test case;
--build-timeout, --build-memory per step's build). Where bubblewrap cannot create
namespaces the grader says so and refuses, unless --no-isolation. The tests write their
results to a file, so what the student's code prints only counts against the output limit.
A failing exercise says why: time limit, memory limit, output limit, crashed: SIGNAME,
failed: <first failing assertion>, does not compile: <first error or the limit it hit>.
The points table goes to the terminal, a JUnit XML file to --junit (default WORK/grade.xml;
the reason is each failure's message), and with --json FILE the same results per exercise
as JSON (exercise, title, step, points, max, status, reason, case, seconds).
WORK/build is kept between runs, so grading the next tree rebuilds only what changed. The
test cases run in folders under WORK that go when grading ends: nothing is left in /tmp.
"""
import argparse
import contextlib
import dataclasses
import json
import os
import re
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time
import traceback
import xml.etree.ElementTree as ET
from dataclasses import dataclass

from . import ROOT, sandbox
from .strict_numbers import MAX_JOBS, MAX_MB, MAX_SECONDS, decimal, integer, step_list
from .exercises import (BEGIN, MAX_RESULT_BYTES, SOURCE_SUFFIXES, case_results, exercises, step_dirs,
                        step_sources)
from .kit import strip_solutions, tracked_files


class GradeError(Exception):
    """Grading cannot start or go on: a bad option, a tree that is not a workbook, the
    grading tree does not configure, no isolation. The message is one line; `code` is the
    exit status of ./workbook grade."""

    def __init__(self, message, code=1):
        super().__init__(message)
        self.code = code


class OutOfTime(Exception):
    """The whole grading of one tree passed its deadline (the class grader's
    --student-timeout)."""


# What XML 1.0 forbids (C0 controls but tab and newline here, also carriage return; U+FFFE,
# U+FFFF; lone surrogates), and DEL and the C1 controls, which drive terminals.
_UNPRINTABLE = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\ud800-\udfff\ufffe\uffff]")


def printable(text):
    """text with each such character written as \\xNN or \\uNNNN: what the student's code prints,
    throws or names goes into the JUnit XML (which must stay well-formed), the JSON and the
    instructor's terminal."""
    return _UNPRINTABLE.sub(lambda m: f"\\x{ord(m.group()):02x}" if ord(m.group()) < 0x100
                            else f"\\u{ord(m.group()):04x}", text)


def say(text, log=None):
    print(f"[grade] {text}", file=log or sys.stderr, flush=True)


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
        raise GradeError(f"grade: --hidden {hidden}: no such folder")
    for f in sorted(os.listdir(hidden)):
        m = re.match(r"(?:test_)?step(\d\d)", f)
        if not f.endswith(".cpp"):
            continue
        if not m or m.group(1) not in step_numbers:
            raise GradeError(f"grade: hidden test {f}: name it stepNN*.cpp for one of the steps "
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


HIDDEN_DIR = "tests/hidden"  # where the grading tree keeps the hidden tests


def hidden_copies(work, number=None):
    """The grading tree's copies of the hidden tests (of step `number`, or all)."""
    folder = os.path.join(work, "src", HIDDEN_DIR)
    if not os.path.isdir(folder):
        return []
    return [os.path.join(folder, n) for n in sorted(os.listdir(folder))
            if number is None or n.startswith(f"step{number}_")]


def set_hidden_mode(work, mode, number=None):
    """chmod the hidden tests' copies: 0 while student code runs or a student's own source
    compiles (not even their owner may read them then: bubblewrap's nobody is the grader
    outside), readable only while they compile themselves."""
    for path in hidden_copies(work, number):
        os.chmod(path, mode)


def assemble(student, hidden, work, steps):
    """Writes the grading tree into work/src; returns the notes for the report. The hidden
    tests' copies get neutral names (tests/hidden/stepNN_K.cpp: nothing in the tree says
    what the instructor called them) and are left unreadable (set_hidden_mode)."""
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
    extra = ["", "# Added by tools/grading/grade.py: the instructor's hidden tests."]
    for number, names in by_step.items():
        if number not in steps:
            continue
        copies = []
        for k, n in enumerate(names):
            with open(os.path.join(hidden, n), "rb") as f:
                files[f"{HIDDEN_DIR}/step{number}_{k}.cpp"] = f.read()
            copies.append(f"hidden/step{number}_{k}.cpp")
        sources = " ".join(copies)
        extra.append(f"if(TARGET test_step{number})\n    target_sources(test_step{number} PRIVATE {sources})\nendif()")
        notes.append(f"hidden tests for step {number}: {', '.join(names)}")
    if len(extra) > 2:
        files["tests/CMakeLists.txt"] += ("\n".join(extra) + "\n").encode()
    set_hidden_mode(work, 0o600)  # the grader compares and rewrites them
    sync_tree(os.path.join(work, "src"), files)
    set_hidden_mode(work, 0)
    return notes


# Building and running ------------------------------------------------------------------------


@dataclass
class Isolation:
    """How student code runs: isolated or not, and the limits of a build and of a test case."""
    isolate: bool
    build: sandbox.Limits
    test: sandbox.Limits
    jobs: int = 2
    # What student code must not read: the reference tree (the solutions), the student's own
    # tree, the instructor's hidden tests and home folders. It reads the grading tree instead
    # (a build: WORK/src and WORK/build; a test: WORK/build and the data).
    hidden: tuple = ()
    deadline: float = None  # time.monotonic() by which the whole grading ends (None: none)
    log: object = None  # where progress goes (None: stderr)
    # Without isolation, as root: the unprivileged user student code runs as (a
    # sandbox.User). The grading tree is then readable to it, the build folder its own only
    # while it builds, each test case's folder its own; the rest is the grader's.
    user: sandbox.User = None

    @property
    def drop(self):
        return self.user is not None and not self.isolate


def chown_tree(path, uid, gid):
    """chown -R without following links."""
    os.lchown(path, uid, gid)
    for d, dirs, files in os.walk(path):
        for n in dirs + files:
            os.lchown(os.path.join(d, n), uid, gid)


@contextlib.contextmanager
def building(work, iso):
    """While a configure or a build runs: WORK/build is the student user's (its compilers
    write there), afterwards the grader's again, so that the tests, which run the student's
    code as that user, cannot change what later builds and tests use."""
    build = os.path.join(work, "build")
    if not iso.drop:
        yield
        return
    chown_tree(build, iso.user.uid, iso.user.gid)
    try:
        yield
    finally:
        chown_tree(build, os.getuid(), os.getgid())


def share_tree(src):
    """The grading tree readable to everyone (the compilers run as the student user; root's
    umask may be 077), but for the hidden tests (set_hidden_mode)."""
    os.chmod(src, 0o755)
    for d, dirs, files in os.walk(src):
        if os.path.relpath(d, src) == HIDDEN_DIR:
            continue
        for n in dirs:
            os.chmod(os.path.join(d, n), 0o755)
        for n in files:
            path = os.path.join(d, n)
            if not os.path.islink(path):
                os.chmod(path, 0o755 if os.stat(path).st_mode & 0o100 else 0o644)


# Run as the student user: which of the paths it can open (a folder: list).
_ACCESS_PROBE = """import json, os, sys
seen = {}
for p in sys.argv[1:]:
    try:
        os.listdir(p) if os.path.isdir(p) else open(p, "rb").close()
        seen[p] = True
    except OSError:
        seen[p] = False
print(json.dumps(seen))
"""


def check_user_access(iso, work, secret):
    """Asks the student user itself (a command in the sandbox, as the tests run) what it can
    read: the grading tree it must, the reference tree and the hidden tests it must not.
    Raises GradeError (exit 2) naming what is wrong."""
    src = os.path.join(work, "src")
    wanted = [src, os.path.join(src, "CMakeLists.txt")]
    paths = wanted + [p for p in secret if p and os.path.exists(p)]
    with tempfile.TemporaryDirectory(prefix="probe-", dir=work) as folder:
        os.chmod(folder, 0o711)
        os.chown(folder, iso.user.uid, iso.user.gid)
        r = sandbox.run([sandbox.USER_PYTHON, "-I", "-S", "-c", _ACCESS_PROBE] + paths,
                        sandbox.Limits(seconds=30, memory_mb=1024, output_mb=1), writable=[folder],
                        isolate=False, env=clean_env(folder), user=iso.user)
    try:
        seen = json.loads(r.stdout.decode())
    except ValueError:
        raise GradeError(f"grade: cannot run commands as user {iso.user.name} ({r.reason}: "
                         f"{r.stderr.decode(errors='replace').strip()[-200:]})", 2) from None
    for p in wanted:
        if not seen.get(p):
            raise GradeError(f"grade: user {iso.user.name} cannot read the grading tree {src}: "
                             "every folder above it must let others in (chmod o+x)", 2)
    for p in paths[len(wanted):]:
        if seen.get(p):
            raise GradeError(f"grade: user {iso.user.name} can read {p}: the reference solutions "
                             "and the hidden tests must be out of its reach (chmod o-rwx on it or "
                             "a folder above it)", 2)


def sandboxed(cmd, limits, iso, **kw):
    """sandbox.run with the isolation's settings, within its deadline: a run's time limit
    is cut to the time left, and OutOfTime is raised once none is left."""
    if iso.deadline is not None:
        left = iso.deadline - time.monotonic()
        if left <= 0:
            raise OutOfTime()
        if left < limits.seconds:
            limits = dataclasses.replace(limits, seconds=left)
    r = sandbox.run(cmd, limits, isolate=iso.isolate, hidden=iso.hidden,
                    user=iso.user if iso.drop else None, **kw)
    if iso.deadline is not None and time.monotonic() >= iso.deadline:
        raise OutOfTime()
    return r


def clean_env(home):
    """The environment student code sees: no secrets of the instructor's shell."""
    env = {k: v for k, v in os.environ.items() if k in ("PATH", "LANG", "LC_ALL", "CC", "CXX", "TZ")}
    env.setdefault("PATH", "/usr/local/bin:/usr/bin:/bin")
    # glibc's malloc keeps up to 8 arenas of 64 MB address space per core: on a many-core
    # machine that alone would pass the memory limit.
    env.update(HOME=home, TMPDIR="/tmp", MALLOC_ARENA_MAX="2")
    return env


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
        with building(work, iso):
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


def write_private(path, text):
    """A file only the grader reads (a build log may quote the hidden tests)."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    os.fchmod(fd, 0o600)  # an older one may have been readable
    with os.fdopen(fd, "w") as f:
        f.write(text)


def cmake_build(work, targets, iso):
    """Builds targets (names, or object files by their path in WORK/build) in the sandbox: the
    compilers run on the student's sources, so the build writes only WORK/build, within the
    build limits."""
    build = os.path.join(work, "build")
    with building(work, iso):
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
    r = sandboxed([binary, "--list-test-cases", "--reporters=xml"], limits, iso, writable=[folder],
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
    """One test case in its own sandboxed process, in a fresh writable folder, with the test
    limits. doctest writes its results to a file there, so what the student's code prints is
    only counted against the output limit, never read as a result."""
    os.makedirs(folder)
    if iso.drop:
        os.chown(folder, iso.user.uid, iso.user.gid)
    result = os.path.join(folder, "result.xml")
    cmd = [binary, "--test-suite=" + doctest_filter(suite), "--test-case=" + doctest_filter(name),
           "--reporters=xml", "--no-version", f"--out={result}"]
    try:
        r = sandboxed(cmd, iso.test, iso, writable=[folder], env=clean_env(folder), keep=1 << 16,
                      readable=test_readable(binary))
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


# The report ----------------------------------------------------------------------------------


def print_table(rows, notes, out=sys.stdout):
    total = sum(r["points"] for r in rows)
    earned = sum(r["points"] for r in rows if r["passed"])
    out.write(f"\nGrade: {earned} of {total} points\n\n")
    out.write(f"{'exercise':<9} {'points':>6}  {'result':<7} why it failed\n")
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
                f = ET.SubElement(c, "failure", message=printable(r["message"]), type="failed")
                f.text = printable("\n".join(r["details"]) or r["message"])
            else:
                ET.SubElement(c, "system-out").text = printable("\n".join(r["details"]))
        earned = sum(r["points"] for r in items if r["passed"])
        ET.SubElement(s, "system-out").text = (
            f"step {step}: {earned} of {sum(r['points'] for r in items)} points\n" +
            "".join(f"note: {printable(n)}\n" for n in notes))
    ET.indent(suites)
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    ET.ElementTree(suites).write(path, encoding="utf-8", xml_declaration=True)


def write_json(path, rows, notes, seconds):
    """The per-exercise results as JSON, for batch grading and other tools: one object per
    exercise with its points earned (0 unless passed), max, status (passed, failed, time
    limit, memory limit, output limit, crashed, does not compile, no tests), reason (empty
    when passed), the first failing test case and seconds."""
    doc = {"points": sum(r["points"] for r in rows if r["passed"]),
           "max": sum(r["points"] for r in rows), "seconds": round(seconds, 2),
           "exercises": [{"exercise": r["id"], "title": r["title"], "step": r["step"],
                          "points": r["points"] if r["passed"] else 0, "max": r["points"],
                          "status": r["status"], "reason": r["reason"], "case": r["case"],
                          "seconds": round(r["seconds"], 2)}
                         for r in rows],
           "notes": list(notes)}
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")


def exercise_row(e, number, build_error, outcomes, seconds):
    """The report's row of one exercise: passed when it has test cases and all pass; else the
    reason of its first failing case, of its step's build ('does not compile: ...'), or
    (status, reason) of a test program that does not start."""
    failed = [o for o in outcomes if not o.passed]
    if isinstance(build_error, tuple):  # the test program does not start
        (status, reason), case = build_error, ""
    elif build_error:
        status, reason, case = "does not compile", build_error, ""
    elif not outcomes:
        status, reason, case = "no tests", "no test cases for this exercise", ""
    elif failed:
        status, reason, case = failed[0].status, failed[0].reason, failed[0].name
    else:
        status, reason, case = "passed", "", ""
    reason = printable(reason)
    reason = reason if len(reason) <= 500 else reason[:497] + "..."
    message = reason + (f' (test case "{case}")' if case else "")
    details = [printable(f"{'passed' if o.passed else 'FAILED'}: {o.name}" + ("" if o.passed else f": {o.reason}"))
               for o in outcomes] or [message]
    return {"id": e.id, "title": e.title, "points": e.points, "step": number,
            "passed": status == "passed", "status": status, "reason": reason, "case": case,
            "message": message, "details": details,
            "seconds": sum(o.seconds for o in outcomes) if outcomes else seconds}


def refuse_without_isolation(opts, log=None):
    """The grader runs student code: without bubblewrap it refuses unless told otherwise."""
    if opts.no_isolation:
        say("WARNING: student code runs WITHOUT isolation (--no-isolation): only for code you trust", log)
        return
    problem = sandbox.isolation_problem()
    if problem:
        raise GradeError(f"grade: {problem}: refusing to run student code without isolation "
                         "(--no-isolation runs it unprotected, only for code you trust)", 2)


@dataclass
class GradeOptions:
    """What grading one tree takes besides the tree: the command line's options, with its
    defaults (main() fills it from the command line; the class grader and Gradescope build
    it themselves)."""
    hidden: str = None  # folder of hidden doctest files stepNN*.cpp
    junit: str = None  # the JUnit XML file (None: WORK/grade.xml)
    json: str = None  # the per-exercise JSON file (None: none)
    timeout: float = 60.0  # seconds of one test case, wall clock
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
            program = rel.startswith("tests/test_step") and os.sep not in rel[len("tests/"):]
            if rel in doomed or whole_step or n.endswith(".a") or program:
                os.remove(path)


def grade(student, opts, out=None, log=None, deadline=None, partial=False):
    """Grades the tree `student` with GradeOptions `opts`: the points table to `out`
    (default stdout), progress to `log` (default stderr), the JUnit XML (and the JSON) to
    their files. Raises GradeError when grading cannot start or go on, OutOfTime once
    time.monotonic() passes `deadline` (with `partial`: the exercises not graded by then
    fail with that reason instead), sandbox.Stopped after sandbox.stop_all()."""
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
            user = sandbox.grading_user(opts.user)
        except ValueError as e:
            raise GradeError(f"grade: --user: {e}", 2) from None
    elif opts.no_isolation and os.geteuid() == 0:
        say("WARNING: as root without --user, student code runs as root", log)
    hidden = opts.hidden and os.path.abspath(opts.hidden)
    unreadable = (ROOT, student_path, hidden, os.path.expanduser("~"), "/home", "/root")
    iso = Isolation(not opts.no_isolation,
                    build=sandbox.Limits(opts.build_timeout, opts.build_memory, opts.output, file_mb=2048),
                    test=sandbox.Limits(opts.timeout, opts.memory, opts.output), jobs=opts.jobs,
                    hidden=tuple(dict.fromkeys(p for p in unreadable if p)), deadline=deadline, log=log,
                    user=user)
    os.makedirs(work, exist_ok=True)
    notes = assemble(student_path, hidden, work, steps)
    if iso.drop:
        os.chmod(work, 0o755)
        share_tree(os.path.join(work, "src"))
        solutions = [os.path.join(ROOT, rel) for rel in solution_files()[:1]]
        check_user_access(iso, work, solutions + [hidden] + hidden_copies(work) + list(opts.private))
        notes.append(f"student code ran without isolation, as user {user.name}")
    elif not iso.isolate:
        notes.append("student code ran without isolation (--no-isolation)")
    configure(work, iso)
    rows = []
    # The test cases' folders: in WORK (the clone's build/ by default), not the shared /tmp,
    # and removed when grading ends, however it ends.
    with tempfile.TemporaryDirectory(prefix="scratch-", dir=work, ignore_cleanup_errors=True) as scratch:
        if iso.drop:
            os.chmod(scratch, 0o711)  # the user reaches its case folders, lists nothing
        for k, number in enumerate(steps):
            items = [e for e in all_ex if f"{e.step:02d}" == number]
            say(f"step {number}: building test_step{number}", log)
            t0 = time.monotonic()
            try:
                step_rows = grade_step(work, number, items, iso, scratch, notes, log, t0)
            except OutOfTime:
                if not partial:
                    raise
                why = ("time limit", "not graded: the grading ran past its overall time limit")
                for later in steps[k:]:
                    rows += [exercise_row(e, later, why, [], 0.0) for e in all_ex if f"{e.step:02d}" == later]
                say(f"out of time at step {number}: its exercises and the later ones are not graded", log)
                break
            rows += step_rows
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


def results_by_exercise(rows):
    """The rows as the class grader and Gradescope keep them, one dict per exercise:
    exercise, title, step, max, passed, points (earned), status, reason (with the first
    failing test case in front), details (a line per test case), seconds."""
    results = []
    for r in rows:
        reason = r["reason"]
        if r["case"] and not r["passed"] and r["case"] not in reason:
            reason = f"{r['case']}: {reason}"
        details = "\n".join(r["details"]) or r["message"]
        results.append({"exercise": r["id"], "title": r["title"], "step": r["step"], "max": r["points"],
                        "passed": r["passed"], "points": r["points"] if r["passed"] else 0,
                        "status": r["status"], "reason": reason,
                        "details": [line for line in details.splitlines() if line.strip()],
                        "seconds": round(r["seconds"], 2)})
    return results


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
    exercises not graded in time fail instead). sandbox.Stopped passes."""
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
                   help="time limit of one test case in seconds, wall clock (default %(default)g)")
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
        print(e, file=sys.stderr)
        return e.code
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
