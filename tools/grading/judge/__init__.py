"""The judge: the grader's test cases run as a trusted checker and a sandboxed worker.

The checker of step NN is the reference's test program of that step (the tests, the
reference's code but for the exercises) built from a copy of the reference tree in which
every exercise function's body calls the worker instead (stubs.py); it holds every expected
value and decides every verdict, and runs no student code and compiles no student file. The
worker of step NN is the student's step sources (and the steps they link) with a call server
(worker.hpp), and no test at all: it receives one call's arguments at a time and answers with
the result. For each test case the grader starts a fresh checker and a fresh worker, joined by
two pipes (wire.hpp); the worker runs in the student's sandbox, the checker outside it.

Hidden tests (--hidden DIR) are compiled into a second checker per step
(judge_hidden_stepNN: the visible tests and the hidden ones); the visible cases run in the
first, which has no hidden test in it. The checkers are built once into their own folder
(the judge folder, mode 0700: no sandbox mounts it, the student's user cannot enter it) and
reused for every student graded with the same reference and hidden tests. The cases to run
are listed by the checker (a trusted program), each with the file it comes from: a case is
hidden when its file is one of the hidden tests, whatever doctest form declares it.
"""
import dataclasses
import fcntl
import os
import re
import select
import shutil
import stat
import struct
import subprocess
import threading
import time
import xml.etree.ElementTree as ET
from dataclasses import dataclass

from .. import sandbox
from ..exercises import case_results, exercises, step_dirs
from . import stubs

HERE = os.path.dirname(os.path.abspath(__file__))
HIDDEN_DIR = "tests/hidden"  # where the checker's tree keeps the hidden tests
# The checker is trusted code that reads the worker's answers: the standard library's bounds
# checks (vector, span, array), fortified string functions and stack canaries stop it at the
# first index a wrong answer would take out of range, instead of reading or writing the
# checker's memory.
CHECKER_FLAGS = "-O1 -DNDEBUG -D_GLIBCXX_ASSERTIONS -D_FORTIFY_SOURCE=2 -fstack-protector-strong"


class JudgeError(Exception):
    """The checker cannot be built or listed: the reference or the hidden tests are at fault,
    not the student (one line; the build log is in the judge folder)."""


# What is generated from the reference ------------------------------------------------------


def signatures(root):
    """{exercise id: stubs.Signature} of every exercise in `root`'s steps."""
    found = {}
    texts = {}
    for e in exercises(root):
        if e.path not in texts:
            with open(os.path.join(root, e.path), encoding="utf-8") as f:
                texts[e.path] = f.read()
        found[e.id] = stubs.parse_signature(e, texts[e.path])
    return found


def _cmake_graph(root):
    """({library: step number}, {target: [linked targets]}) from the steps' and the tests'
    CMake files: which step's code a test program links."""
    libraries, links = {}, {}
    files = [os.path.join(root, "tests", "CMakeLists.txt")]
    for d in step_dirs(root):
        for base, _, names in os.walk(d):
            files += [os.path.join(base, n) for n in names if n == "CMakeLists.txt"]
    for path in files:
        with open(path, encoding="utf-8") as f:
            text = re.sub(r"#[^\n]*", "", f.read())
        for m in re.finditer(r"add_library\(\s*(step(\d\d)_\w+)", text):
            libraries[m.group(1)] = m.group(2)
        for m in re.finditer(r"target_link_libraries\(\s*(\S+)([^)]*)\)", text):
            links.setdefault(m.group(1), []).extend(
                w for w in m.group(2).split() if w not in ("PUBLIC", "PRIVATE", "INTERFACE"))
        for m in re.finditer(r"boxes_add_test\(\s*test_step\$\{number\}[^)]*LIBS\s+step\$\{step\}", text):
            for d in step_dirs(root):
                name = os.path.basename(d)
                links.setdefault(f"test_step{name[:2]}", []).append(f"step{name}")
        for m in re.finditer(r"boxes_add_test\(\s*(test_step\d\d)[^)]*LIBS\s+([^)]*)\)", text):
            links.setdefault(m.group(1), []).extend(m.group(2).split())
    return libraries, links


def served_steps(root):
    """{step: [steps whose exercises its test program can reach]}, from the CMake links."""
    libraries, links = _cmake_graph(root)
    numbers = sorted({f"{e.step:02d}" for e in exercises(root)})
    served = {}
    for n in numbers:
        seen, todo = set(), [f"test_step{n}"]
        while todo:
            t = todo.pop()
            if t in seen:
                continue
            seen.add(t)
            todo += links.get(t, [])
        reach = {libraries[t] for t in seen if t in libraries} | {n}
        served[n] = sorted(s for s in reach if s in numbers)
    return served


def step_library(root, number):
    """The step's own library (add_library(stepNN_name ...) in its folder)."""
    libraries, _ = _cmake_graph(root)
    for lib, n in libraries.items():
        if n == number and re.fullmatch(rf"step{number}_[a-z0-9]+", lib):
            return lib
    raise JudgeError(f"judge: step {number} has no library stepNN_name in its CMakeLists.txt")


def types_headers(steps):
    return [f"judge/types_{n}.hpp" if os.path.exists(os.path.join(HERE, f"types_{n}.hpp"))
            else "judge/types_core.hpp" for n in steps]


def checker_files(root, hidden_by_step):
    """{relative path: bytes} of the checker's source tree: the reference's files, each
    exercise's body a call of its proxy, the proxies, the hidden tests and the CMake lines
    that build the hidden checkers."""
    from ..kit import tracked_files

    sigs = signatures(root)
    by_file = {}
    for s in sigs.values():
        by_file.setdefault(s.path, []).append(s)
    files = {}
    for rel in tracked_files(root):
        if rel.startswith(("slides/", "out/")):
            continue
        path = os.path.join(root, rel)
        if rel in by_file:
            with open(path, encoding="utf-8") as f:
                files[rel] = stubs.checker_text(f.read(), by_file[rel]).encode()
        elif rel == "tests/test_main.cpp":
            with open(path, encoding="utf-8") as f:
                files[rel] = _checker_main(f.read()).encode()
        else:
            with open(path, "rb") as f:
                files[rel] = f.read()
    numbers = sorted({s.id.split(".")[0].zfill(2) for s in sigs.values()})
    top = ["", "# Added by the grader (tools/grading/judge): the checker's exercises call the worker."]
    top.append("target_include_directories(boxes_core PUBLIC ${PROJECT_SOURCE_DIR}/tools/grading)")
    for n in numbers:
        mine = sorted((s for s in sigs.values() if stubs.step_of(s.path) == n), key=lambda s: tuple(map(int, s.id.split("."))))
        files[f"judge/proxies_{n}.cpp"] = stubs.proxies_source(mine, types_headers([n])).encode()
        top.append(f"target_sources({step_library(root, n)} PRIVATE ${{PROJECT_SOURCE_DIR}}/judge/proxies_{n}.cpp)")
    files["CMakeLists.txt"] += ("\n".join(top) + "\n").encode()
    extra = ["", "# Added by the grader (tools/grading/judge): the hidden checkers, the visible tests"
             " and the hidden ones."]
    for number, names in sorted(hidden_by_step.items()):
        copies = []
        for k, (name, data) in enumerate(names):
            files[f"{HIDDEN_DIR}/step{number}_{k}.cpp"] = data
            copies.append(f"hidden/step{number}_{k}.cpp")
        extra.append(
            f"if(TARGET test_step{number})\n"
            f"    get_target_property(judge_sources test_step{number} SOURCES)\n"
            f"    get_target_property(judge_libraries test_step{number} LINK_LIBRARIES)\n"
            f"    add_executable(judge_hidden_step{number} ${{judge_sources}} {' '.join(copies)})\n"
            f"    target_link_libraries(judge_hidden_step{number} PRIVATE ${{judge_libraries}})\n"
            "endif()")
    files["tests/CMakeLists.txt"] += ("\n".join(extra) + "\n").encode()
    return files


def _checker_main(text):
    """The checkers' main: doctest takes the case to run from the environment too
    (judge/checker_main.hpp)."""
    context = "doctest::Context context(argc, argv);"
    if context not in text or "#include <doctest/doctest.h>" not in text:
        raise JudgeError("judge: tests/test_main.cpp has no doctest::Context context(argc, argv) "
                         "to give the case's filters to")
    text = text.replace("#include <doctest/doctest.h>",
                        '#include <doctest/doctest.h>\n#include "judge/checker_main.hpp"', 1)
    return text.replace(context, context + "\n    ::boxes::judge::applyCaseFilters(context);", 1)


def worker_files(root, steps):
    """{relative path: bytes} the grading tree (the student's) gets: a server per step and
    the CMake lines that build it as judge_worker_NN from what test_stepNN links, but no test."""
    sigs = signatures(root)
    served = served_steps(root)
    files = {}
    lines = ["", "# Added by the grader (tools/grading/judge): one worker per step, the student's "
             "exercise functions behind a call server; no test."]
    for n in steps:
        mine = sorted((s for s in sigs.values() if stubs.step_of(s.path) in served[n]),
                      key=lambda s: tuple(map(int, s.id.split("."))))
        files[f"judge/worker_{n}.cpp"] = stubs.worker_source(mine, types_headers(served[n])).encode()
        lines.append(
            f"if(TARGET test_step{n})\n"
            f"    add_executable(judge_worker_{n} ${{PROJECT_SOURCE_DIR}}/judge/worker_{n}.cpp)\n"
            f"    get_target_property(judge_libraries test_step{n} LINK_LIBRARIES)\n"
            "    list(REMOVE_ITEM judge_libraries boxes_test_main)\n"
            f"    target_link_libraries(judge_worker_{n} PRIVATE ${{judge_libraries}} boxes_core)\n"
            f"    target_include_directories(judge_worker_{n} PRIVATE ${{PROJECT_SOURCE_DIR}}/tools/grading)\n"
            "endif()")
    return files, "\n".join(lines) + "\n"


# The checker's build -------------------------------------------------------------------------


@dataclass
class Case:
    suite: str
    name: str
    file: str  # the source file doctest names for it (in the checker's tree)
    hidden: bool

    @property
    def exercise(self):
        return self.suite.split(" ", 1)[1] if self.suite.startswith("exercise ") else None


@dataclass
class Checker:
    """The built checkers of one step and the cases they list."""
    visible: str  # test_stepNN in the judge folder
    hidden: str  # judge_hidden_stepNN, or None without hidden tests for the step
    cases: list  # [Case] in the order to run: the visible ones first
    folder: str  # the judge folder


def _private_dir(path):
    os.makedirs(path, exist_ok=True)
    os.chmod(path, 0o700)


def _sync(dest, files):
    """dest holds exactly `files`, written 0600 in 0700 folders (the hidden tests among
    them); unchanged files keep their time stamps so the build redoes only what changed."""
    old_umask = os.umask(0o077)
    try:
        for rel, data in files.items():
            path = os.path.join(dest, rel)
            try:
                with open(path, "rb") as f:
                    if f.read() == data:
                        continue
            except OSError:
                pass
            os.makedirs(os.path.dirname(path), exist_ok=True)
            tmp = path + ".tmp"
            with open(tmp, "wb") as f:
                f.write(data)
            os.replace(tmp, path)
        wanted = {os.path.normpath(r) for r in files}
        for d, _, names in os.walk(dest, topdown=False):
            for n in names:
                rel = os.path.normpath(os.path.relpath(os.path.join(d, n), dest))
                if rel not in wanted:
                    os.remove(os.path.join(d, n))
            if d != dest and not os.listdir(d):
                os.rmdir(d)
    finally:
        os.umask(old_umask)


def _configured(build, entries):
    """Whether the build folder is configured with these CMake cache entries."""
    try:
        with open(os.path.join(build, "CMakeCache.txt"), encoding="utf-8", errors="replace") as f:
            cache = dict(line.split("=", 1) for line in f.read().splitlines()
                         if "=" in line and not line.startswith(("//", "#")))
    except OSError:
        return False
    values = {k.split(":")[0]: v for k, v in cache.items()}
    return (os.path.exists(os.path.join(build, "build.ninja"))
            and all(values.get(k) == v for k, v in entries.items()))


def _run_logged(cmd, log_path, timeout):
    """A trusted command (the checker's configure and build): its output appended to a
    private log; (ok, last lines)."""
    fd = os.open(log_path, os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o600)
    with os.fdopen(fd, "a") as log:
        log.write("$ " + " ".join(cmd) + "\n")
        log.flush()
        try:
            r = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT, timeout=timeout,
                               stdin=subprocess.DEVNULL)
            ok = r.returncode == 0
        except subprocess.TimeoutExpired:
            log.write(f"[judge] timed out after {timeout:g} s\n")
            ok = False
    return ok


def prepare(root, folder, hidden_by_step, steps, cache, jobs=2, timeout=3600, say=print):
    """Builds (or brings up to date) the checkers of `steps` in `folder` and lists their cases:
    {step: Checker}. `hidden_by_step`: {step: [(file name, bytes)]}; `cache`: the CMake
    cache entries of the grading build. Runs as the grader, outside any sandbox: it compiles
    the reference and the hidden tests, never a student's file. Raises JudgeError."""
    _private_dir(folder)
    with open(os.path.join(folder, "lock"), "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # one build at a time (the class grader's jobs share it)
        src, build = os.path.join(folder, "src"), os.path.join(folder, "build")
        _sync(src, checker_files(root, hidden_by_step))
        _private_dir(build)
        log = os.path.join(folder, "build.log")
        entries = dict(cache, CMAKE_CXX_FLAGS_RELEASE=CHECKER_FLAGS)
        launcher = shutil.which("ccache") if os.environ.get("BOXES_GRADE_CCACHE", "1") != "0" else None
        if launcher:
            # Paths hashed relative to the checkers' sources (ccache's base_dir): every grading
            # folder, class worker and clone compiles the same files, so they share the objects.
            entries["CMAKE_CXX_COMPILER_LAUNCHER"] = ";".join(
                ["env", f"CCACHE_BASEDIR={os.path.realpath(src)}", "CCACHE_NOHASHDIR=1", launcher])
        if not _configured(build, entries):
            say("judge: configuring the checkers (once; later grades reuse them)")
            if not _run_logged(["cmake", "-S", src, "-B", build, "-G", "Ninja"] +
                               [f"-D{k}={v}" for k, v in entries.items()], log, timeout):
                raise JudgeError(f"judge: the checkers' tree does not configure: see {log}")
        targets = [f"test_step{n}" for n in steps] + [f"judge_hidden_step{n}" for n in steps
                                                        if hidden_by_step.get(n)]
        say(f"judge: building the checkers of step{'s' if len(steps) > 1 else ''} {', '.join(steps)}")
        if not _run_logged(["cmake", "--build", build, "--target", *targets, "--", f"-j{jobs}"],
                           log, timeout):
            raise JudgeError(f"judge: the checkers do not build (the reference's tests or the hidden "
                             f"tests do not compile with the reference): see {log}")
        checkers = {}
        hidden_folder = os.path.join(src, HIDDEN_DIR) + os.sep
        for n in steps:
            visible = os.path.join(build, "tests", f"test_step{n}")
            hidden = os.path.join(build, "tests", f"judge_hidden_step{n}") if hidden_by_step.get(n) else None
            listed = list_cases(hidden or visible)
            # doctest names a case's file as the compiler saw it: relative to the build folder
            # (a compiler cache rewrites paths so) or absolute.
            cases = [Case(s, name, f, os.path.normpath(os.path.join(build, f)).startswith(hidden_folder))
                     for s, name, f in listed if s.startswith("exercise ")]
            cases.sort(key=lambda c: c.hidden)  # stable: the visible ones first, in their order
            checkers[n] = Checker(visible, hidden, cases, folder)
        return checkers


def list_cases(binary):
    """[(suite, name, file)] of a checker: a trusted program (no student code), so its own
    list is the grader's."""
    r = subprocess.run([binary, "--list-test-cases", "--reporters=xml", "--no-version"],
                       capture_output=True, timeout=120, stdin=subprocess.DEVNULL,
                       env={"PATH": "/usr/bin:/bin"})
    try:
        return listed_cases(r.stdout)
    except JudgeError:
        raise JudgeError(f"judge: {binary} does not list its test cases "
                         f"({r.stderr.decode(errors='replace').strip()[-200:]})") from None


def listed_cases(stdout):
    """[(suite, name, file)] from doctest's --list-test-cases --reporters=xml output, or
    JudgeError when it is no such list."""
    try:
        doc = ET.fromstring(stdout.decode(errors="replace"))
    except ET.ParseError:
        raise JudgeError("judge: no list of test cases") from None
    return [(c.get("testsuite", ""), c.get("name", ""), c.get("filename", ""))
            for c in doc.iter("TestCase")]


# One test case -------------------------------------------------------------------------------


@dataclass
class Ends:
    """The two commands' results of one case."""
    checker: object  # sandbox.Result
    worker: object  # sandbox.Result (None when it never ran)
    result: bytes  # the checker's doctest XML (None when it wrote none)


# The shared slots of the protocol's fast path (wire.hpp's SharedChannel: two slots of
# 1 MiB and their counters).
SHARED_BYTES = 2 * (3 * 64 + (1 << 20))


def shared_slots():
    """Two descriptors of one sealed memfd of SHARED_BYTES zeros (its size cannot change:
    a worker that shrank it would make the checker fault), or None where there is none."""
    try:
        fd = os.memfd_create("boxes-judge", os.MFD_CLOEXEC | os.MFD_ALLOW_SEALING)
    except (AttributeError, OSError):
        return None
    try:
        os.ftruncate(fd, SHARED_BYTES)
        import fcntl as _fcntl
        _fcntl.fcntl(fd, _fcntl.F_ADD_SEALS, _fcntl.F_SEAL_SHRINK | _fcntl.F_SEAL_GROW | _fcntl.F_SEAL_SEAL)
        return fd, os.dup(fd)
    except (AttributeError, OSError):
        os.close(fd)
        return None


def run_pair(checker_run, worker_run, fast=False):
    """Runs the worker (worker_run(pass_fds, fds_text)) on a thread and the checker
    (checker_run likewise) on this one, joined by two pipes (and with `fast`, shared slots
    where both can have a core: wire.hpp); returns (checker's result, worker's result).
    Each run function must hand its descriptors to sandbox.run, which closes this process's
    copies once its command started: then either command sees the end of the pipes when
    the other ends."""
    to_worker = os.pipe()
    to_checker = os.pipe()
    worker_fds = (to_worker[0], to_checker[1])
    checker_fds = (to_checker[0], to_worker[1])
    shared = shared_slots() if fast else None
    if shared:
        worker_fds += (shared[0],)
        checker_fds += (shared[1],)
    box = {}

    def worker():
        try:
            box["worker"] = worker_run(worker_fds, ",".join(map(str, worker_fds)))
        except BaseException as e:  # sandbox.Stopped, say: raised here after the checker ends
            box["error"] = e

    thread = threading.Thread(target=worker, daemon=True)
    try:
        thread.start()
    except BaseException:
        for fd in worker_fds + checker_fds:
            os.close(fd)
        raise
    try:
        checker = checker_run(checker_fds, ",".join(map(str, checker_fds)))
    finally:
        thread.join()
    if "error" in box:
        raise box["error"]
    return checker, box.get("worker")


# The verdict of one case ------------------------------------------------------------------------

WORKER_GONE = 75  # the checker's exit status when its worker ended in a call (codec.hpp)
WORKER_MALFORMED = 76  # ... when its worker's answer broke the protocol
LIMITS = ("time limit", "memory limit", "output limit", "crashed")


def verdict(checker, worker, found):
    """(status, reason) of a case from the checker's and the worker's sandbox results and the
    checker's doctest results for it (found: [CaseResult], [] when it wrote none). Only the
    checker's own result can pass a case, and only when its worker ended as it should (when
    the checker closed the pipes)."""
    last = (checker.stderr.decode(errors="replace").strip().splitlines() or [""])[-1][:300]
    if checker.returncode == WORKER_GONE and "[judge]" in last:
        if worker is not None and worker.status in LIMITS:
            return worker.status, worker.reason
        how = "" if worker is None else f" ({worker.reason if not worker.ok else 'exit 0'})"
        return "failed", f"failed: {last.split('] ', 1)[-1]}{how}"
    if checker.returncode == WORKER_MALFORMED and "[judge]" in last:
        return "failed", f"failed: {last.split('] ', 1)[-1]}"
    if checker.status in LIMITS:
        # The checker waits for its worker: a worker over a limit is the reason.
        if worker is not None and worker.status in LIMITS:
            return worker.status, worker.reason
        return checker.status, checker.reason
    if found and not found[0].passed:
        message = found[0].message
        if "bad_alloc" in message:  # the worker's refused allocation, thrown on here
            return "memory limit", "memory limit"
        return "failed", f"failed: {message or 'the test case failed'}"
    if found and checker.ok:
        if worker is None or worker.ok:
            return "passed", ""
        if worker.status in LIMITS:
            return worker.status, worker.reason
        return "failed", f"failed: the test passed, then its worker ended with {worker.reason}"
    why = "no test result" + ("" if checker.ok else f", {checker.reason}")
    return "failed", f"failed: {why} (the grader's checker{': ' + last if last else ''})"


@dataclass
class Runner:
    """What the cases of one graded tree need: the isolation (grade.Isolation) and where
    their folders go."""
    iso: object
    scratch: str  # the workers' case folders (the grading run's scratch)
    private: str  # the checkers' case folders: in the judge folder, 0700
    worker_readable: list  # what a worker reads: its build, the data
    judge_folder: str  # the checkers' folder: no worker sees it


# A case's time limit is the CPU time of its worker (the student's code), as in IOI's and
# DOMjudge's judges; its wall clock may run WALL_FACTOR times as long. A case makes up to a
# few hundred thousand calls between checker and worker, each a wake-up of the other
# process: on a loaded machine the scheduler's delays, not the student's code, would
# otherwise decide the verdict. A worker that sleeps or waits still meets the wall clock.
WALL_FACTOR = 3.0


def case_limits(iso):
    """The worker's limits of one case (or probe): CPU seconds the test time limit, the wall
    clock WALL_FACTOR times it, both within the grading run's deadline."""
    from ..errors import OutOfTime

    limits = iso.test
    wall = limits.seconds * WALL_FACTOR
    if iso.deadline is not None:
        left = iso.deadline - time.monotonic()
        if left <= 0:
            raise OutOfTime()
        wall = min(wall, left)
    return dataclasses.replace(limits, seconds=wall, cpu=min(limits.seconds, wall))


def run_case(runner, checker, case, worker_binary, folder_name):
    """(status, reason, seconds) of one case: a fresh checker and a fresh worker."""
    from ..box import clean_env
    from ..build_and_run import doctest_filter, read_result
    from ..errors import OutOfTime

    iso = runner.iso
    limits = case_limits(iso)
    # The checker waits on its worker: a little longer, so that a worker past its limit is
    # the reason, not the checker that waited for it.
    checker_limits = dataclasses.replace(limits, seconds=limits.seconds + 2, cpu=0.0)
    wfolder = os.path.join(runner.scratch, folder_name)
    cfolder = os.path.join(runner.private, folder_name)
    os.makedirs(wfolder)
    os.makedirs(cfolder, mode=0o700)
    if iso.drop:
        os.chown(wfolder, iso.user.uid, iso.user.gid)
    result = os.path.join(cfolder, "result.xml")
    binary = checker.hidden if case.hidden else checker.visible
    cmd = [binary, "--reporters=xml", "--no-version", f"--out={result}"]
    # The case by its file, suite and name, in the environment (checker_main.hpp): only the
    # grader's user can read it, where every user could read a command line.
    case_env = {"BOXES_JUDGE_FILE": doctest_filter(case.file), "BOXES_JUDGE_SUITE": doctest_filter(case.suite),
                "BOXES_JUDGE_CASE": doctest_filter(case.name)}
    started = time.monotonic()

    # The checker is the grader's own code: it runs as the grader, under the test limits but
    # outside bubblewrap (a second sandbox per case would double its start-up cost). What
    # the worker sends it is read with bounds checks (judge/wire.hpp, codec.hpp) and it is
    # built with the standard library's and the compiler's checks (CHECKER_FLAGS).
    def checker_run(fds, text):
        return sandbox.run(cmd, checker_limits, writable=[cfolder], cwd=cfolder, isolate=False,
                           env=dict(clean_env(cfolder), BOXES_JUDGE_FDS=text, **case_env),
                           keep=1 << 16, pass_fds=fds)

    try:
        c, w = run_pair(checker_run, _worker_run(runner, worker_binary, wfolder, limits),
                        fast=sandbox.usable_cpus() >= 2)
        data = read_result(result)
        found = [x for x in case_results(data) if x.name == case.name] if data else []
        _machine_check(iso, c, w)
    finally:
        shutil.rmtree(wfolder, ignore_errors=True)
        shutil.rmtree(cfolder, ignore_errors=True)
        if iso.drop:
            remove_left_behind(iso.user.uid)
    if iso.deadline is not None and time.monotonic() >= iso.deadline:
        raise OutOfTime()
    status, reason = verdict(c, w, found)
    return status, reason, time.monotonic() - started


def _worker_run(runner, worker_binary, wfolder, limits):
    """How a worker runs: in the student's sandbox, its folder a scratch space of the test's
    disk limit (sandbox.run scratch=), the judge's folder out of sight."""
    from ..box import clean_env

    iso = runner.iso

    def worker_run(fds, text):
        return sandbox.run([worker_binary], limits, scratch=wfolder, isolate=iso.isolate,
                           env=dict(clean_env(wfolder), BOXES_JUDGE_FDS=text), keep=1 << 16,
                           hidden=tuple(iso.hidden) + (runner.judge_folder,),
                           readable=runner.worker_readable, user=iso.user if iso.drop else None,
                           pass_fds=fds)
    return worker_run


def _machine_check(iso, *results):
    """A run that failed on a full grading disk is the machine's failure: NotGraded (the
    box's rule, box.sandboxed), never points lost."""
    from ..box import disk_trouble
    from ..errors import NotGraded

    if iso.disk and any(r is not None and not r.ok for r in results):
        trouble = disk_trouble(iso.disk)
        if trouble:
            raise NotGraded(trouble)


def _frame(kind, payload):
    return struct.pack("<IB3x", len(payload), kind) + payload


def _text(s):
    return struct.pack("<Q", len(s)) + s


def ping(fds, seconds):
    """Calls the worker's built-in "judge.ping" on the pipes fds (read, write) and waits up
    to `seconds` for its answer; True when it answered. Closes fds."""
    read_fd, write_fd = fds
    try:
        try:
            os.write(write_fd, _frame(1, _text(b"judge.ping") + _text(b"")))
        except OSError:
            return False
        deadline = time.monotonic() + seconds
        got = b""
        while len(got) < 8:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([read_fd], [], [], left)[0]:
                return False
            chunk = os.read(read_fd, 8 - len(got))
            if not chunk:
                return False
            got += chunk
        size, kind = struct.unpack("<IB3x", got)
        return kind == 2 and size == 0
    finally:
        for fd in fds:
            os.close(fd)


def probe(runner, worker_binary, folder_name):
    """'' when the step's worker starts and answers a call, else why not (a global object's
    constructor that never ends, a crash or an exit before main): then no case of the step
    can pass, and the grader does not wait for each case to find out."""
    from ..errors import OutOfTime

    iso = runner.iso
    limits = case_limits(iso)
    wfolder = os.path.join(runner.scratch, folder_name)
    os.makedirs(wfolder)
    if iso.drop:
        os.chown(wfolder, iso.user.uid, iso.user.gid)
    answered = {}

    def asker(fds, text):
        answered["ok"] = ping(fds, limits.seconds)
        return None

    try:
        _, w = run_pair(asker, _worker_run(runner, worker_binary, wfolder, limits))
        if not answered.get("ok"):
            _machine_check(iso, w)
    finally:
        shutil.rmtree(wfolder, ignore_errors=True)
        if iso.drop:
            remove_left_behind(iso.user.uid)
    if iso.deadline is not None and time.monotonic() >= iso.deadline:
        raise OutOfTime()
    if answered.get("ok"):
        return ""
    if w is None or w.ok or w.status == "failed":
        how = "exit 0" if w is None or w.ok else w.reason[len("failed: "):]
        return ("failed", f"failed: the step's worker ended ({how}) before its first call "
                          "(the student's code runs before main?)")
    return (w.status, f"{w.reason} (the step's worker does not start)")


# Without bubblewrap the student's user shares the machine's /tmp: what one worker leaves
# there (a hidden case's input, say) a later worker could read.
SHARED_WRITABLE = ("/tmp", "/var/tmp", "/dev/shm")


_open_below_closed = {}


def _others_may_write(mode):
    return stat.S_ISDIR(mode) and mode & stat.S_IWOTH


def open_folders(places):
    """The folders below `places` that every user may write although their parent folder is
    not: found once per process (one walk of the whole tree). A user can create an entry only
    in a folder it may write, so these and the places themselves are where a worker's files
    can start; a walk of everything (a clone's build folder in /tmp, tens of thousands of
    entries) after every case cost a second or two each."""
    key = tuple(places)
    if key not in _open_below_closed:
        found = []
        for top in places:
            for d, dirs, _ in os.walk(top):
                try:
                    closed = not _others_may_write(os.lstat(d).st_mode)
                except OSError:
                    continue
                for n in dirs:
                    try:
                        if closed and _others_may_write(os.lstat(os.path.join(d, n)).st_mode):
                            found.append(os.path.join(d, n))
                    except OSError:
                        pass
        _open_below_closed[key] = found
    return _open_below_closed[key]


def remove_left_behind(uid, places=SHARED_WRITABLE):
    """Removes what the user `uid` owns in the folders every user may write (links are
    removed, never followed); the count removed. It looks where the user could create an
    entry: in those folders, in the ones below them that every user may write too, and in
    open_folders' (a folder the user may write through its group or an ACL only is not
    searched: the student's user has a group of its own and no ACL)."""
    removed = 0
    todo = [p for p in list(places) + open_folders(places) if os.path.isdir(p)]
    seen = set()
    while todo:
        folder = todo.pop()
        if folder in seen:
            continue
        seen.add(folder)
        try:
            entries = list(os.scandir(folder))
        except OSError:
            continue
        for entry in entries:
            try:
                info = entry.stat(follow_symlinks=False)
            except OSError:
                continue
            if info.st_uid != uid:
                if _others_may_write(info.st_mode):
                    todo.append(entry.path)
                continue
            try:
                if stat.S_ISDIR(info.st_mode):
                    shutil.rmtree(entry.path)
                else:
                    os.unlink(entry.path)
                removed += 1
            except OSError:
                pass
    return removed
