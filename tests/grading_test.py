#!/usr/bin/python3
"""End-to-end tests of the starter kit and of grading (ctest label "grading").

usage: python3 -m tests.grading_test SCENARIO WORK_DIR
  kit            the kit has no solution line left, a stub per exercise, everything else equal
  reference      the reference tree scores full points
  kit-zero       the starter kit scores zero, each failure naming its exercise
  one-solved     a kit with one exercise solved scores exactly that exercise's points
  compile-error  a step that does not compile scores zero with the compiler's error; the
                 other graded steps keep their points
  hidden         an instructor's hidden tests count (also one named with a comma), and a
                 hanging test case stops at the time limit
  hostile-loop, hostile-segv, hostile-memory, hostile-files, hostile-read, hostile-network,
  hostile-output, hostile-static, hostile-compile, hostile-compile-time
                 the reference with one exercise's solution replaced by hostile code (an
                 endless loop, a null-pointer write, allocating without limit, writing files
                 outside its folder, reading the solutions, the network, printing without
                 end, a global object that never ends its constructor, a compile that eats
                 memory, a compile that never ends): the report is
                 complete, the other exercises keep their points, the hostile one scores
                 zero with its reason, and nothing outside the sandbox changed (skipped,
                 exit 77, where bubblewrap cannot run)
  no-isolation   where bubblewrap cannot create namespaces (a fake bwrap that fails) the
                 grader refuses in one line, and grades with --no-isolation
  judge-*        the judge against hostile student code: tests/judge_test.py
  each-solved    (by hand, not in ctest) each exercise solved alone scores exactly its points

The steps are discovered, not named: grading scenarios use the first step with exercises
(and the last one for the compile error), so they keep working as steps are added. All
grading scenarios share one grading build in WORK_DIR (ctest runs them one at a time).
"""
import json
import os
import socket
import shutil
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

from tools import ROOT
from tools.grading.exercises import BEGIN, END, exercises, step_sources
from tools.grading.kit import NOT_IN_KIT, strip_solutions, write_kit
from tools.grading.sandbox import isolation_problem

# The grader as ./workbook grade runs it: a module of the tools package, from the root.
GRADE = [sys.executable, "-m", "tools.grading.grade"]

SKIPPED = 77  # ctest's SKIP_RETURN_CODE

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


def isolation_flags():
    """The grading scenarios test grading, not isolation: where bubblewrap cannot run they
    grade without it (the hostile scenarios are skipped there instead)."""
    problem = isolation_problem()
    if problem:
        print(f"note: {problem}: grading with --no-isolation")
        return ["--no-isolation"]
    return []


def grade(student, work, steps, junit):
    cmd = GRADE + [student, "--work", work, "--steps", ",".join(steps), "--junit", junit,
                   "--timeout", "120"] + isolation_flags()
    r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
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
    check(not any(os.path.exists(os.path.join(dest, rel)) for rel in NOT_IN_KIT) and
          not os.path.exists(os.path.join(dest, "tools", "grading", "grade.py")), "no grader in the kit")
    check(not os.path.exists(os.path.join(dest, "tests", "mutants")) and
          os.path.isfile(os.path.join(dest, "tests", "hints", "mistakes.json")),
          "no mistakes' patches in the kit (their hints are)")


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
                    f'TEST_SUITE("exercise {ids[1]}") {{\n'
                    '    TEST_CASE("hidden: a name with a comma, which doctest filters split") { CHECK(true); }\n}\n'
                    f'TEST_SUITE("exercise {hanging}") {{\n'
                    '    TEST_CASE("hidden: a test that never ends") {\n'
                    "        for (;;) std::this_thread::sleep_for(std::chrono::milliseconds(10));\n"
                    "    }\n}\n")
        # 30 s: the judge's heaviest cases of step 01 (a few hundred thousand calls through
        # its pipes) take seconds, more on a loaded machine; the hanging case waits it out.
        cmd = GRADE + [ROOT, "--work", work, "--steps", first, "--junit", os.path.join(work, "hidden.xml"),
                       "--timeout", "30", "--hidden", hidden] + isolation_flags()
        r = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
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


# Hostile student trees ------------------------------------------------------------------------

HOSTILE_INCLUDES = "".join(f"#include <{h}>\n" for h in (
    "arpa/inet.h", "netdb.h", "netinet/in.h", "sys/socket.h", "unistd.h", "cerrno", "cstdint",
    "cstdio", "cstring", "stdexcept", "string", "vector"))


def c_string(text):
    return json.dumps(text)  # a C string literal for plain ASCII paths


def hostile_body(kind, token, work, port):
    """The statements that replace the hostile exercise's solution: each either never returns
    or throws, so it compiles in any function whatever its return type."""
    if kind == "loop":
        return ["for (volatile unsigned long spin = 0;; spin = spin + 1) {", "}"]
    if kind == "segv":
        return ["volatile std::uintptr_t address = 0;",
                "*reinterpret_cast<volatile int*>(address) = 1;  // a null-pointer write",
                'throw std::logic_error("survived a null-pointer write");']
    if kind == "memory":
        return ["std::vector<char*> blocks;", "for (;;) {",
                "    char* block = new char[1 << 24];",
                "    for (int i = 0; i < (1 << 24); i += 4096) reinterpret_cast<volatile char*>(block)[i] = 1;",
                "    blocks.push_back(block);", "}"]
    if kind == "files":
        paths = ", ".join(c_string(p) for p in hostile_paths(token, work))
        return ["std::string report;",
                f"for (const char* path : {{{paths}}}) {{",
                '    if (std::FILE* f = std::fopen(path, "a")) {',
                '        std::fputs("written by hostile student code\\n", f);',
                "        std::fclose(f);",
                '        report += std::string("wrote ") + path + "; ";',
                "    } else {",
                '        report += std::string(path) + ": " + std::strerror(errno) + "; ";',
                "    }", "}",
                f"if (std::remove({c_string(canary_path(work))}) == 0) report += \"removed the canary; \";",
                "throw std::runtime_error(report);"]
    if kind == "read":  # the reference solutions, the grader, the tests' sources
        paths = ", ".join(c_string(p) for p in secret_paths(work))
        return ["std::string report;",
                f"for (const char* path : {{{paths}}}) {{",
                '    if (std::FILE* f = std::fopen(path, "r")) {',
                '        report += std::string("read ") + path + "; ";',
                "        std::fclose(f);",
                "    } else {",
                '        report += std::string("cannot read ") + path + " (" + std::strerror(errno) + "); ";',
                "    }", "}",
                "throw std::runtime_error(report);"]
    if kind == "network":
        return ["std::string report;",
                "int s = socket(AF_INET, SOCK_STREAM, 0);",
                "sockaddr_in address{};",
                "address.sin_family = AF_INET;",
                f"address.sin_port = htons({port});",
                'inet_pton(AF_INET, "127.0.0.1", &address.sin_addr);',
                "if (s >= 0 && connect(s, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0)",
                '    report += "connected to the listener; ";',
                "else",
                '    report += std::string("connect: ") + std::strerror(errno) + "; ";',
                "if (s >= 0) close(s);",
                "addrinfo* found = nullptr;",
                'int rc = getaddrinfo("example.com", "80", nullptr, &found);',
                'if (rc == 0) { report += "resolved example.com"; freeaddrinfo(found); }',
                'else report += std::string("resolve example.com: ") + gai_strerror(rc);',
                "throw std::runtime_error(report);"]
    if kind == "output":
        return ["std::string line(1 << 16, 'x');", "line.back() = '\\n';",
                "for (;;) std::fwrite(line.data(), 1, line.size(), stdout);"]
    if kind == "static":  # the solution kept; a global object that never ends its constructor
        return None
    if kind == "compile":
        return ['#include "/dev/zero"']
    if kind == "compile-time":
        # Minutes of constant evaluation. GCC stops one evaluation after 2^33 operations
        # (-fconstexpr-ops-limit), which a fast machine reaches within the build's time
        # limit, so: 64 evaluations, each below that cap, each with its own argument (GCC
        # caches a constexpr call's result).
        return ["constexpr auto spin = [](unsigned long k) {", "    unsigned long n = k;",
                "    for (unsigned long i = 0; i < 30000; ++i)",
                "        for (unsigned long j = 0; j < 30000; ++j) n += i ^ j ^ k;",
                "    return n;", "};"] + [f"static_assert(spin({k}) != 1);" for k in range(64)] + [
                'throw std::logic_error("compiled");']
    raise ValueError(kind)


def hostile_paths(token, work):
    """Where the files scenario tries to write: the instructor's home, the grader's source
    tree, the shared /tmp and /var/tmp, and the grading tree's build recipe and tests."""
    name = f"boxes-hostile-{token}"
    return [os.path.join(os.path.expanduser("~"), name), os.path.join(ROOT, name),
            os.path.join("/tmp", name), os.path.join("/var/tmp", name), canary_path(work),
            os.path.join(work, "build", "build.ninja"),
            os.path.join(work, "src", "tests", "step01_triangle.cpp")]


def secret_paths(work):
    """What the read scenario tries to read: the reference's solutions and the grader's
    source, and the grading tree's test sources."""
    first = exercises(ROOT)[0]
    return [os.path.join(ROOT, first.path), os.path.join(ROOT, "tools", "grading", "grade.py"),
            os.path.join(work, "src", "tests", "step01_triangle.cpp")]


def canary_path(work):
    return os.path.join(work, "canary.txt")


def hostile_tree(dest, exercise, body):
    """The reference's step sources with one exercise's solution replaced by `body`."""
    student_tree(dest)
    path = os.path.join(dest, exercise.path)
    with open(path, encoding="utf-8") as f:
        lines = f.read().split("\n")
    if body is None:  # runs before any test: at the program's start
        lines.append("namespace { struct Spin { Spin() { for (volatile int i = 0;; i = i + 1) {} } } spin; }")
    else:
        lines[exercise.begin + 1:exercise.end] = ["    " + l for l in body]
    with open(path, "w", encoding="utf-8") as f:
        f.write(HOSTILE_INCLUDES + "\n".join(lines))


def snapshot(work):
    """What must not change: the source tree's git status, the canary and the grading tree's
    build recipe and test file."""
    status = subprocess.run(["git", "-C", ROOT, "status", "--porcelain"], capture_output=True,
                            text=True).stdout
    files = {}
    for p in (canary_path(work), os.path.join(work, "build", "build.ninja"),
              os.path.join(work, "src", "tests", "step01_triangle.cpp")):
        with open(p, "rb") as f:
            files[p] = f.read()
    return status, files


# kind: (the expected status, a text the reason contains, extra grade.py flags)
HOSTILE = {
    "loop": ("time limit", "time limit", ["--timeout", "4"]),
    "segv": ("crashed", "crashed: SIGSEGV", []),
    "memory": ("memory limit", "memory limit", ["--memory", "320"]),
    "files": ("failed", "failed: threw: ", []),  # each path refused: see scenario_hostile
    "read": ("failed", "cannot read", []),
    "network": ("failed", "connect: ", []),
    "output": ("output limit", "output limit", ["--output", "4"]),
    "static": ("time limit", "time limit (the step's worker does not start)",
               ["--timeout", "3", "--build-timeout", "120"]),
    "compile": ("does not compile", "does not compile: memory limit", ["--build-memory", "1024"]),
    "compile-time": ("does not compile", "does not compile: time limit", ["--build-timeout", "10"]),
}


def scenario_hostile(work, kind):
    problem = isolation_problem()
    if problem:
        print(f"SKIP: {problem}")
        return SKIPPED
    first = steps_with_exercises()[0]
    ids = [e.id for e in exercises(ROOT) if f"{e.step:02d}" == first]
    hostile = [e for e in exercises(ROOT) if e.id == ids[-1]][0]
    want_status, want_text, flags = HOSTILE[kind]
    token = f"{os.getpid()}-{kind}"
    listener = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    listener.bind(("127.0.0.1", 0))
    listener.listen(8)
    listener.setblocking(False)
    port = listener.getsockname()[1]
    os.makedirs(os.path.join(work, "build"), exist_ok=True)
    with open(canary_path(work), "w") as f:
        f.write("the grader's own file\n")
    json_path = os.path.join(work, f"hostile-{kind}.json")
    started = time.monotonic()
    with tempfile.TemporaryDirectory() as student:
        hostile_tree(student, hostile, hostile_body(kind, token, work, port))
        cmd = GRADE + [student, "--work", work, "--steps", first, "--junit",
                       os.path.join(work, f"hostile-{kind}.xml"), "--json", json_path, "--timeout", "30"] + flags
        before = snapshot(work) if os.path.exists(os.path.join(work, "build", "build.ninja")) else None
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=600, cwd=ROOT)
    seconds = time.monotonic() - started
    print(r.stdout, r.stderr[-3000:])
    check(r.returncode == 0, f"{kind}: grade.py exits 0 ({seconds:.1f} s)")
    check(len(r.stdout) < 20000, f"{kind}: the report is short ({len(r.stdout)} characters)")
    results = {}
    if os.path.exists(json_path):
        with open(json_path) as f:
            results = {x["exercise"]: x for x in json.load(f)["exercises"]}
    check(sorted(results) == sorted(ids), f"{kind}: the report has every exercise of step {first}")
    got = results.get(hostile.id, {})
    # The reason is the first failing case's; what the hostile code did may show in a later
    # case's line (the first may be one that words its failure its own way).
    said = "\n".join([got.get("reason", "")] + got.get("details", []))
    check(got.get("points") == 0 and got.get("status") == want_status and want_text in said,
          f"{kind}: exercise {hostile.id} scores 0: {got.get('status')!r}, {got.get('reason', '')[:300]!r}")
    lines = {l.split()[0]: l for l in r.stdout.splitlines() if l[:1].isdigit()}
    check(want_text.split(":")[0] in lines.get(hostile.id, ""), f"{kind}: the table says why: {lines.get(hostile.id)!r}")
    if kind.startswith("compile") or kind == "static":  # the whole step fails; the report is complete
        check(all(results.get(i, {}).get("status") == want_status for i in ids),
              f"{kind}: every exercise of step {first}: {want_status}")
    else:
        others = [i for i in ids if i != hostile.id]
        check(all(results.get(i, {}).get("status") == "passed" for i in others),
              f"{kind}: every other exercise passes: " +
              ", ".join(f"{i} {results.get(i, {}).get('status')}" for i in others))
        check(f"Grade: {points(others)} of {points(ids)} points" in r.stdout,
              f"{kind}: {points(others)} of {points(ids)} points")
    # Nothing outside the sandbox changed.
    for p in hostile_paths(token, work)[:4]:
        check(not os.path.exists(p), f"{kind}: no file {p}")
        if os.path.exists(p):
            os.remove(p)
    if before is not None:
        after = snapshot(work)
        check(after[0] == before[0], f"{kind}: the source tree's git status did not change")
        for p, data in before[1].items():
            check(after[1][p] == data, f"{kind}: {os.path.relpath(p, work)} did not change")
    if kind == "read":
        for p in secret_paths(work):
            check(f"cannot read {p} (No such file or directory)" in said,
                  f"{kind}: {p} is not there for the student's code")
    if kind == "files":
        check("wrote /tmp/" in said, f"{kind}: the private /tmp was writable (and is gone)")
        # Every other place refused the write with its error (not there, not the sandbox's
        # user's, or read-only): none of them was written.
        for p in hostile_paths(token, work):
            if not p.startswith("/tmp/"):
                check(f"{p}: " in said and f"wrote {p}" not in said,
                      f"{kind}: writing {p} was refused")
    try:
        connection, _ = listener.accept()
        connection.close()
        check(False, f"{kind}: a connection reached the listener on port {port}")
    except BlockingIOError:
        check(True, f"{kind}: no connection reached the listener on port {port}")
    listener.close()
    return None


def scenario_no_isolation(work):
    """A bubblewrap that cannot create namespaces (a fake one): the grader refuses in one
    plain line and builds nothing; with --no-isolation it grades."""
    first = steps_with_exercises()[0]
    fake = os.path.join(work, "fake-bwrap")
    with open(fake, "w") as f:
        f.write("#!/bin/sh\necho 'bwrap: No permissions to create a new namespace' >&2\nexit 1\n")
    os.chmod(fake, 0o755)
    env = dict(os.environ, BOXES_BWRAP=fake)
    json_path = os.path.join(work, "no-isolation.json")
    if os.path.exists(json_path):
        os.remove(json_path)
    base = GRADE + [ROOT, "--work", work, "--steps", first, "--json", json_path, "--junit",
                    os.path.join(work, "no-isolation.xml")]
    r = subprocess.run(base, capture_output=True, text=True, env=env, cwd=ROOT)
    print(r.stdout, r.stderr)
    check(r.returncode != 0, f"refused: exit {r.returncode}")
    check(len(r.stderr.strip().splitlines()) == 1 and "cannot create namespaces" in r.stderr
          and "--no-isolation" in r.stderr, "refused: one plain line naming the problem and the flag")
    check(not os.path.exists(json_path) and "Grade:" not in r.stdout, "refused: nothing graded")
    r = subprocess.run(base + ["--no-isolation"], capture_output=True, text=True, env=env, cwd=ROOT)
    print(r.stdout, r.stderr)
    ids = [e.id for e in exercises(ROOT) if f"{e.step:02d}" == first]
    check(r.returncode == 0 and f"Grade: {points(ids)} of {points(ids)} points" in r.stdout,
          "--no-isolation: graded, full points")
    check("without isolation" in r.stdout and "WITHOUT isolation" in r.stderr,
          "--no-isolation: the report and the terminal say the code ran without isolation")


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
    scenarios = {"kit": scenario_kit, "reference": scenario_reference, "kit-zero": scenario_kit_zero,
                 "one-solved": scenario_one_solved, "compile-error": scenario_compile_error,
                 "hidden": scenario_hidden, "no-isolation": scenario_no_isolation,
                 "each-solved": scenario_each_solved}
    for kind in HOSTILE:
        scenarios[f"hostile-{kind}"] = lambda w, kind=kind: scenario_hostile(w, kind)
    if scenario not in scenarios:
        print(__doc__, file=sys.stderr)
        return 2
    if scenarios[scenario](work) == SKIPPED:
        return SKIPPED
    print(f"{len(failures)} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
