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
  judge-garbage  student code writes frames of its own into the judge's pipe: those
                 exercises fail as a broken protocol, the others keep their points
  judge-forged, judge-exit-list, judge-hidden (and each with -fallback: without bubblewrap,
                 as root, the student's code as a user of its own; skipped, 77, when not root)
                 the judge against hostile student code: a result forged before main and an
                 exit 0 score nothing; an exit 0 inside an exercise fails it; a case list
                 filtered of hidden and failing cases changes nothing; hidden tests in every doctest form are hidden and
                 counted, and spying code (its own program run with --success, and a header
                 that breaks doctest's macros) learns nothing of them that reaches what a student sees
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


# The judge: hostile student code against the checker and the worker ---------------------------
# Each judge-* scenario runs under bubblewrap, and with -fallback appended without it, as
# Gradescope's container runs it: as root, the student's code as an unprivileged user of its
# own (created here, removed after; skipped, 77, when not root).

FORGE = r"""
#include <fcntl.h>
#include <unistd.h>
#include <cstdio>
#include <cstring>
#include <string>
namespace {
// Before main: a doctest result that says the case the command line names passed, written
// wherever a result may be read (--out=, stdout, the working folder), then exit 0. Asked for
// its list of cases, the program answers truly: a grader that runs the student's test
// program then reads a forged pass for every case.
struct ForgedResult {
    ForgedResult() {
        std::string args, out = "result.xml", name = "forged";
        if (FILE* f = std::fopen("/proc/self/cmdline", "rb")) {
            char buf[8192];
            size_t n = std::fread(buf, 1, sizeof buf, f);
            std::fclose(f);
            for (size_t i = 0; i < n;) {
                std::string a(buf + i);
                i += a.size() + 1;
                if (a.rfind("--out=", 0) == 0) out = a.substr(6);
                if (a.rfind("--test-case=", 0) == 0) name = a.substr(12);
                if (a == "--list-test-cases") return;  // the list honest, so every case is run
            }
        }
        std::string xml = "<?xml version=\"1.0\"?><doctest><TestSuite name=\"exercise 1.1\"><TestCase name=\"" +
                          name + "\"><OverallResultsAsserts successes=\"1\" failures=\"0\" test_case_success=\"true\"/>"
                          "</TestCase></TestSuite><OverallResultsAsserts successes=\"1\" failures=\"0\"/>"
                          "<OverallResultsTestCases successes=\"1\" failures=\"0\"/></doctest>\n";
        for (const std::string& path : {out, std::string("result.xml"), std::string("/tmp/result.xml")})
            if (FILE* f = std::fopen(path.c_str(), "w")) {
                std::fputs(xml.c_str(), f);
                std::fclose(f);
            }
        std::fputs(xml.c_str(), stdout);
        std::fflush(stdout);
        _exit(0);
    }
} forgedResult;
}  // namespace
"""

# The case list filtered at the source: asked for its cases, the program asks itself again
# and prints that list without the hidden tests' cases (tests/hidden/) and without exercise
# 1.6's (whose solution below is wrong): a grader that trusted the list would run neither.
FILTER_LIST = r"""
#include <sys/wait.h>
#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>
namespace {
struct FilteredList {
    FilteredList() {
        if (std::getenv("BOXES_FILTER_CHILD")) return;
        std::string args;
        if (FILE* f = std::fopen("/proc/self/cmdline", "rb")) {
            char buf[8192];
            size_t n = std::fread(buf, 1, sizeof buf, f);
            std::fclose(f);
            args.assign(buf, n);
        }
        if (args.find("--list-test-cases") == std::string::npos) return;
        std::vector<char*> argv;
        for (size_t i = 0; i < args.size(); i += std::string(&args[i]).size() + 1) argv.push_back(&args[i]);
        argv.push_back(nullptr);
        int fds[2];
        if (pipe(fds) != 0) return;
        if (fork() == 0) {
            dup2(fds[1], 1);
            setenv("BOXES_FILTER_CHILD", "1", 1);
            execv("/proc/self/exe", argv.data());
            _exit(127);
        }
        close(fds[1]);
        std::string list;
        char chunk[4096];
        for (ssize_t n; (n = read(fds[0], chunk, sizeof chunk)) > 0;) list.append(chunk, n);
        wait(nullptr);
        std::string kept;  // one <TestCase .../> element a line, in doctest's XML listing
        for (size_t at = 0; at < list.size();) {
            size_t end = list.find('\n', at);
            if (end == std::string::npos) end = list.size();
            std::string line = list.substr(at, end - at + 1);
            at = end + 1;
            if (line.find("<TestCase") != std::string::npos &&
                (line.find("hidden") != std::string::npos || line.find("exercise 1.6") != std::string::npos))
                continue;
            kept += line;
        }
        std::fputs(kept.c_str(), stdout);
        std::fflush(stdout);
        _exit(0);
    }
} filteredList;
}  // namespace
"""

# An instructor's hidden test that any solution fails: dropped from a filtered list, it would
# cost nothing.
FAILING_HIDDEN = ('#include <doctest/doctest.h>\nTEST_SUITE("exercise 1.2") {\n'
                  '    TEST_CASE("hidden: an instructor check the list drops") { CHECK(1 + 1 == 3); }\n}\n')


# What only the hidden tests hold, put together here so that this file (which the grading
# tree holds) and the spy's code never hold them whole.
SECRET = "SECRET-" + "7c41"  # in the hidden tests' names
SECRET_INPUT = "4242." + "4"  # the start of the hidden cases' distinctive input as printed
SECRET_VALUE = "8675." + "309"  # an expected value only the hidden tests hold


def hidden_tests_in_every_form(folder):
    """Hidden tests of step 01's exercises in the doctest forms a regex over the sources
    missed: TEST_SUITE_BEGIN/END, TEST_CASE_FIXTURE, a test_suite decorator with SUBCASEs, and
    a plain TEST_SUITE block; each calls its exercise with a distinctive input."""
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "step01_forms.cpp"), "w") as f:
        f.write(f"""#include <doctest/doctest.h>
#include <cmath>
#include "01_triangle/triangle.hpp"
using namespace boxes;
namespace {{
const float kSecretInput = 4242.0f + 0.42432f;
volatile double secretExpected = {SECRET_VALUE};
struct SecretFixture {{
    Triangle tri{{{{0, 0, 0}}, {{kSecretInput, 0, 0}}, {{0, kSecretInput, 0}}}};
}};
}}  // namespace
TEST_SUITE_BEGIN("exercise 1.1");
TEST_CASE("{SECRET} begin-end form") {{
    auto p = trianglePlane(Triangle{{{{0, 0, kSecretInput}}, {{1, 0, kSecretInput}}, {{0, 1, kSecretInput}}}});
    REQUIRE(p.has_value());
    CHECK(p->d == doctest::Approx(-kSecretInput));
    CHECK(secretExpected > 1.0);
}}
TEST_SUITE_END();
TEST_CASE_FIXTURE(SecretFixture, "{SECRET} fixture form" * doctest::test_suite("exercise 1.4")) {{
    auto h = intersectMollerTrumbore(Ray({{1, 1, 1}}, {{0, 0, -1}}), tri);
    REQUIRE(h.has_value());
    CHECK(h->t == doctest::Approx(1.0));
}}
TEST_CASE("{SECRET} decorator form" * doctest::test_suite("exercise 1.6")) {{
    SUBCASE("{SECRET} subcase") {{
        Vec3 n = interpolateNormal(Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1), 0.0f, 1.0f / kSecretInput);
        CHECK(std::abs(glm::length(n) - 1.0f) < 1e-5f);
    }}
}}
TEST_SUITE("exercise 1.5") {{
    TEST_CASE("{SECRET} suite block form") {{
        auto h = intersectWatertight(Ray({{1, 1, 1}}, {{0, 0, -1}}), Triangle{{{{0, 0, 0}}, {{kSecretInput, 0, 0}}, {{0, kSecretInput, 0}}}});
        CHECK(h.has_value());
    }}
}}
""")
    return 4  # hidden cases


def spy_code(paths):
    """Student code that spies: every exercise call leaves its input where a later worker
    might look, and looks for what other cases left or hold (files left in the shared
    folders, other processes' command lines and environments, the judge's folder, the hidden
    tests, the checkers) and runs its own program with --success; what it finds goes into an
    exception, which a case's failure shows."""
    places = ", ".join(c_string(p) for p in paths)
    return r"""
#include <dirent.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>
namespace boxes_spy {
inline void grab(const std::string& path, std::string& found, int depth = 0) {
    if (depth > 6 || found.size() > (8u << 20)) return;
    const std::string mine = "/boxes-spy-" + std::to_string(getpid());  // this worker's own
    if (path.size() >= mine.size() && path.compare(path.size() - mine.size(), mine.size(), mine) == 0) return;
    if (DIR* d = opendir(path.c_str())) {
        while (dirent* e = readdir(d))
            if (std::strcmp(e->d_name, ".") && std::strcmp(e->d_name, ".."))
                grab(path + "/" + e->d_name, found, depth + 1);
        closedir(d);
        return;
    }
    if (FILE* f = std::fopen(path.c_str(), "rb")) {
        std::vector<char> buf(1 << 20);
        size_t n = std::fread(buf.data(), 1, buf.size(), f);
        std::fclose(f);
        found.append(buf.data(), n);
        found += "\n";
    }
}
inline void look(const char* exercise, const std::string& input) {
    static bool looked = false;  // once per worker (one case): the search is slow
    if (looked) return;
    looked = true;
    if (std::getenv("BOXES_SPY_CHILD")) return;
    std::string found;
    // Its own program run again with --success: were the hidden cases in it, every one would
    // print its name, its inputs and each assertion with its values.
    int fds[2];
    if (pipe(fds) == 0) {
        if (fork() == 0) {
            dup2(fds[1], 1);
            dup2(fds[1], 2);
            setenv("BOXES_SPY_CHILD", "1", 1);
            alarm(30);
            char* argv[] = {(char*)"spy", (char*)"--success", (char*)"--no-skip", nullptr};
            execv("/proc/self/exe", argv);
            _exit(127);
        }
        close(fds[1]);
        char chunk[4096];
        for (ssize_t n; (n = read(fds[0], chunk, sizeof chunk)) > 0 && found.size() < (8u << 20);)
            found.append(chunk, n);
        close(fds[0]);
        wait(nullptr);
    }
    for (const char* dir : {"/tmp", "/var/tmp", "/dev/shm", "."}) grab(dir, found, 5);
    if (DIR* d = opendir("/proc")) {
        while (dirent* e = readdir(d))
            if (e->d_name[0] >= '0' && e->d_name[0] <= '9') {
                grab(std::string("/proc/") + e->d_name + "/cmdline", found, 6);
                grab(std::string("/proc/") + e->d_name + "/environ", found, 6);
            }
        closedir(d);
    }
    for (const char* place : {""" + places + r"""}) grab(place, found);
    const std::string prefixes[] = {"SECRET-", "8675.", "4242."}, suffixes[] = {"7c41", "309", "4"};
    for (int k = 0; k < 3; ++k) {
        std::string needle = prefixes[k] + suffixes[k];  // never whole in this binary
        size_t at = found.find(needle);
        if (at != std::string::npos)
            throw std::runtime_error(std::string("the spy learned: ") +
                                     found.substr(at > 200 ? at - 200 : 0, 400));
    }
    // This case's input, left for a later worker.
    for (const char* dir : {"/tmp", "/var/tmp", "/dev/shm", "."}) {
        std::string path = std::string(dir) + "/boxes-spy-" + std::to_string(getpid());
        if (FILE* f = std::fopen(path.c_str(), "a")) {
            std::fprintf(f, "%s %s\n", exercise, input.c_str());
            std::fclose(f);
        }
    }
}
template <typename... T>
std::string text(const T&... values) {
    std::string s;
    auto add = [&](const auto& v) {
        const unsigned char* p = reinterpret_cast<const unsigned char*>(&v);
        for (size_t i = 0; i + 4 <= sizeof v; i += 4) {
            float x;
            std::memcpy(&x, p + i, 4);
            char b[32];
            std::snprintf(b, sizeof b, "%.9g ", double(x));
            s += b;
        }
    };
    (add(values), ...);
    return s;
}
}  // namespace boxes_spy
"""


def spy_tree(dest, paths):
    """The reference's step sources; every exercise of step 01 spies before its solution, and
    a header breaks doctest's macros (the compile-log trick: were a hidden test compiled with
    it, the compiler would quote the hidden test's lines into the log)."""
    student_tree(dest)
    ids = [e for e in exercises(ROOT) if e.step == 1]
    by_file = {}
    for e in ids:
        by_file.setdefault(e.path, []).append(e)
    for rel, items in by_file.items():
        path = os.path.join(dest, rel)
        with open(path, encoding="utf-8") as f:
            lines = f.read().split("\n")
        for e in sorted(items, key=lambda e: -e.begin):
            args = ", ".join(e.parameters)
            lines.insert(e.begin + 1, f'    boxes_spy::look("{e.id}", boxes_spy::text({args}));')
        with open(path, "w", encoding="utf-8") as f:
            f.write(spy_code(paths) + "\n".join(lines))
    header = os.path.join(dest, "steps", "01_triangle", "triangle.hpp")
    with open(header, encoding="utf-8") as f:
        text = f.read()
    with open(header, "w", encoding="utf-8") as f:
        f.write(text + "\n// The compile-log trick: doctest's macros broken for whatever includes this.\n"
                "#define TEST_CASE(...) static_assert(false, \"broken\");\n"
                "#define TEST_SUITE(...) namespace broken\n#define CHECK(...) CHECK_is_broken\n"
                "#define REQUIRE(...) REQUIRE_is_broken\n")


def fallback_user(work):
    """As root: a fresh unprivileged user for the fallback scenarios (removed at exit)."""
    import atexit
    import hashlib
    name = "boxes-j" + hashlib.sha1(os.path.abspath(work).encode()).hexdigest()[:8]
    subprocess.run(["userdel", name], capture_output=True)
    subprocess.run(["useradd", "--system", "--no-create-home", "--home-dir", "/nonexistent",
                    "--shell", "/usr/sbin/nologin", name], check=True, capture_output=True)
    atexit.register(lambda: subprocess.run(["userdel", name], capture_output=True))
    return name


def judge_grade(mode, student, json_path, hidden=None):
    """grade.py on the student's tree, step 01, in the scenario's mode: (result, {exercise: row})."""
    cmd = [sys.executable, "-m", "tools.grading.grade", student, "--work", mode["work"], "--steps", "01",
           "--junit", os.path.join(mode["work"], "judge.xml"), "--json", json_path, "--timeout", "120"] + mode["flags"]
    if hidden:
        cmd += ["--hidden", hidden]
    if os.path.exists(json_path):
        os.remove(json_path)
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=1800, cwd=mode["root"])
    print(r.stdout, r.stderr[-4000:])
    results = {}
    if os.path.exists(json_path):
        with open(json_path) as f:
            results = {x["exercise"]: x for x in json.load(f)["exercises"]}
    return r, results


def reference_copy(dest):
    """A copy of this tree's files (the grader, the solutions, the tests) in a folder only
    root may enter: the fallback's user must not read the reference (grade.py checks)."""
    from tools.grading.kit import tracked_files
    os.makedirs(dest, exist_ok=True)
    os.chmod(dest, 0o700)
    tree = os.path.join(dest, "tree")
    for rel in tracked_files(ROOT):
        target = os.path.join(tree, rel)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copy2(os.path.join(ROOT, rel), target)
    return tree


def judge_mode(work, fallback):
    """How a judge scenario grades: {root: the tree whose grader runs, work: its grading
    folder, flags: grade.py's}, or None to skip. The fallback is Gradescope's container: as
    root, no bubblewrap, the student's code as an unprivileged user of its own (created here)
    that cannot read the reference."""
    if fallback:
        if os.geteuid() != 0:
            print("SKIP: the fallback runs student code as a user of its own: creating it needs root")
            return None
        base = os.path.join(work, "fallback")
        os.makedirs(base, exist_ok=True)
        os.chmod(base, 0o755)
        return {"root": reference_copy(os.path.join(base, "reference")), "work": os.path.join(base, "grade"),
                "flags": ["--no-isolation", "--user", fallback_user(work)], "user": True}
    problem = isolation_problem()
    if problem:
        print(f"SKIP: {problem}")
        return None
    return {"root": ROOT, "work": work, "flags": [], "user": False}


def scenario_judge_forged(work, fallback):
    """An untouched kit whose code forges a passing result before main and exits 0: every
    exercise scores 0, and the grader says the worker ended before its first call."""
    mode = judge_mode(work, fallback)
    if mode is None:
        return SKIPPED
    ids = [e.id for e in exercises(ROOT) if e.step == 1]
    with tempfile.TemporaryDirectory(dir=work) as student:
        student_tree(student, keep=())
        with open(os.path.join(student, "steps", "01_triangle", "triangle.cpp"), "a") as f:
            f.write(FORGE)
        r, results = judge_grade(mode, student, os.path.join(work, "judge-forged.json"))
    check(r.returncode == 0, "forged: grade.py exits 0")
    check(sorted(results) == sorted(ids), "forged: every exercise of step 01 is in the report")
    for i in ids:
        got = results.get(i, {})
        check(got.get("points") == 0 and "before its first call" in got.get("reason", ""),
              f"forged: exercise {i} scores 0: {got.get('status')!r} {got.get('reason', '')[:200]!r}")
    check("Grade: 0 of" in r.stdout, "forged: zero points")


def scenario_judge_exit_list(work, fallback):
    """The reference, but exercise 1.5 exits 0 inside its function, exercise 1.6 is wrong, a
    hidden test fails exercise 1.2, and the code drops 1.6's and the hidden cases from the list
    of cases it is asked for: 1.2, 1.5 and 1.6 score 0, each with its reason, every other
    exercise passes, and 1.6 runs all its reference cases."""
    mode = judge_mode(work, fallback)
    if mode is None:
        return SKIPPED
    ids = [e.id for e in exercises(ROOT) if e.step == 1]
    by_id = {e.id: e for e in exercises(ROOT)}
    with tempfile.TemporaryDirectory(dir=work) as student:
        hostile_tree(student, by_id["1.5"], ["std::exit(0);  // an early exit, with success"])
        path = os.path.join(student, by_id["1.6"].path)
        with open(path, encoding="utf-8") as f:
            text = f.read()
        wrong = text.replace("Vec3 n = (1.0f - u - v) * na + u * nb + v * nc;",
                             "Vec3 n = (1.0f - u - v) * na + v * nb + u * nc;  // u and v swapped")
        check(wrong != text, "exit-list: exercise 1.6's solution line is found and made wrong")
        with open(path, "w", encoding="utf-8") as f:
            f.write("#include <cstdlib>\n" + wrong + FILTER_LIST)
        hidden = os.path.join(work, "judge-exit-hidden")
        shutil.rmtree(hidden, ignore_errors=True)
        os.makedirs(hidden)
        os.chmod(hidden, 0o700)
        with open(os.path.join(hidden, "step01_dropped.cpp"), "w") as f:
            f.write(FAILING_HIDDEN)
        r, results = judge_grade(mode, student, os.path.join(work, "judge-exit.json"), hidden)
    check(r.returncode == 0, "exit-list: grade.py exits 0")
    got = results.get("1.2", {})
    check(got.get("points") == 0 and "CHECK( 1 + 1 == 3 )" in got.get("reason", "") and got.get("hidden") == 1,
          f"exit-list: the hidden case the list drops runs and fails exercise 1.2: {got.get('reason', '')[:200]!r}")
    got = results.get("1.5", {})
    check(got.get("points") == 0 and "the worker ended while exercise 1.5 ran" in got.get("reason", "")
          and "exit 0" in got.get("reason", ""),
          f"exit-list: exercise 1.5 exits 0 in its call and scores 0: {got.get('reason', '')[:200]!r}")
    got = results.get("1.6", {})
    check(got.get("points") == 0 and got.get("status") == "failed" and "CHECK" in got.get("reason", ""),
          f"exit-list: exercise 1.6 fails its checks: {got.get('reason', '')[:200]!r}")
    others = [i for i in ids if i not in ("1.2", "1.5", "1.6")]
    check(all(results.get(i, {}).get("status") == "passed" for i in others),
          "exit-list: every other exercise passes: " + ", ".join(f"{i} {results.get(i, {}).get('status')}" for i in others))
    # Had the filtered list been the grader's, exercise 1.6 would have had no cases ("no
    # tests") and 1.2 no hidden case: their failed checks show that every case ran.


# Student code that writes into the judge's pipe itself, then answers normally: a frame
# claiming 2 GB, bytes that are no frame, a callback the checker never passed, a frame cut
# short. Each must end its case as a broken protocol, not crash or hang the checker. The
# code waits 0.2 s before answering, so the checker has stopped spinning on the shared slot
# and reads the pipe (a fast answer in the slot leaves what sits in the pipe unread).
GARBAGE = {
    "1.3": "{char f[8] = {0}; uint32_t n = 0x80000000u; std::memcpy(f, &n, 4); f[4] = 2; (void)!write(out, f, 8);}",
    "1.4": "{(void)!write(out, \"\\x05\\x00\\x00\\x00\\x09garbage\", 12);}",
    "1.5": "{char f[12] = {4, 0, 0, 0, 4, 0, 0, 0, 7, 0, 0, 0}; (void)!write(out, f, 12);}",
    "1.6": "{char f[8] = {100, 0, 0, 0, 2, 0, 0, 0}; (void)!write(out, f, 8); close(out);}",
}


def scenario_judge_garbage(work):
    """Student code that writes frames of its own into the judge's pipe: each such exercise
    scores 0 with 'breaks the protocol' (or its worker's end), the others keep their points,
    and grading ends."""
    mode = judge_mode(work, False)
    if mode is None:
        return SKIPPED
    ids = [e.id for e in exercises(ROOT) if e.step == 1]
    by_id = {e.id: e for e in exercises(ROOT)}
    with tempfile.TemporaryDirectory(dir=work) as student:
        student_tree(student)
        by_file = {}
        for i in GARBAGE:
            by_file.setdefault(by_id[i].path, []).append(by_id[i])
        for rel, items in by_file.items():
            path = os.path.join(student, rel)
            with open(path, encoding="utf-8") as f:
                lines = f.read().split("\n")
            for e in sorted(items, key=lambda e: -e.begin):  # from the end: the line numbers hold
                lines.insert(e.begin + 1, "    { int in = -1, out = -1; const char* fds = std::getenv(\"BOXES_JUDGE_FDS\");"
                                          " if (fds && std::sscanf(fds, \"%d,%d\", &in, &out) == 2) {" + GARBAGE[e.id] +
                                          " usleep(200000); } }")
            with open(path, "w", encoding="utf-8") as f:
                f.write("#include <unistd.h>\n#include <cstdint>\n#include <cstdio>\n#include <cstdlib>\n"
                        "#include <cstring>\n" + "\n".join(lines))
        r, results = judge_grade(mode, student, os.path.join(work, "judge-garbage.json"))
    check(r.returncode == 0, "garbage: grade.py exits 0")
    for i in ids:
        got = results.get(i, {})
        if i in GARBAGE:
            check(got.get("points") == 0 and ("breaks the protocol" in got.get("reason", "")
                                              or "the worker ended" in got.get("reason", "")),
                  f"garbage: exercise {i} scores 0: {got.get('status')!r} {got.get('reason', '')[:200]!r}")
        else:
            check(got.get("status") == "passed", f"garbage: exercise {i} keeps its points: {got.get('reason', '')[:200]!r}")


# Grades in-process as Gradescope's run does (grade_into) and writes what Gradescope would
# show (results_json) with the report's results and notes.
GRADESCOPE_DRIVER = """import json, sys
from tools.grading import gradescope
from tools.grading.grade import GradeOptions, grade_into
work, student, hidden, folder, user, out = sys.argv[1:]
opts = GradeOptions(work=work, steps=["01"], hidden=hidden, timeout=120.0, no_isolation=bool(user),
                    user=user or None)
report = grade_into(folder, student, opts)
doc = gradescope.results_json(report.results, {"steps": ["01"], "hidden_visibility": "after_published"},
                              report.notes, report.seconds) if report.code == 0 else {}
with open(out, "w") as f:
    json.dump({"code": report.code, "results": report.results, "gradescope": doc}, f)
"""


def scenario_judge_hidden(work, fallback):
    """Hidden tests in every doctest form against spying student code (and a header that
    breaks doctest's macros): full points, the hidden cases recognised as hidden and counted,
    and nothing of them (names, inputs, expected values) in what a student sees before
    publication (Gradescope's visible tests and output), nor in the grading tree, the
    student's build or its logs. Graded twice: the second run's workers look for what the
    first run's left behind."""
    mode = judge_mode(work, fallback)
    if mode is None:
        return SKIPPED
    grading = mode["work"]
    hidden = os.path.join(work, "judge-hidden-tests")
    shutil.rmtree(hidden, ignore_errors=True)
    count = hidden_tests_in_every_form(hidden)
    os.chmod(hidden, 0o700)
    ids = [e.id for e in exercises(ROOT) if e.step == 1]
    judge_folder = os.path.join(grading, "judge")
    # Where the spy looks besides /tmp, /proc and its own folder: the hidden tests, the judge's
    # folder, the hidden checker, the reference the grader runs (in the fallback a copy only
    # root may enter: this clone itself is the developer's, readable to all).
    places = [hidden, judge_folder, os.path.join(judge_folder, "build", "tests", "judge_hidden_step01"),
              os.path.join(judge_folder, "src", "tests", "hidden"), mode["root"]]
    folder = os.path.join(work, "judge-hidden-report")
    out = os.path.join(work, "judge-hidden.json")
    user = mode["flags"][-1] if mode["user"] else ""
    with tempfile.TemporaryDirectory(dir=work) as student:
        spy_tree(student, places)
        for run in (1, 2):
            shutil.rmtree(folder, ignore_errors=True)
            r = subprocess.run([sys.executable, "-c", GRADESCOPE_DRIVER, grading, student, hidden, folder, user, out],
                               capture_output=True, text=True, timeout=3600, cwd=mode["root"])
            print(r.stdout[-2000:], r.stderr[-2000:])
            if os.path.exists(os.path.join(folder, "grade.log")):
                with open(os.path.join(folder, "grade.log"), errors="replace") as f:
                    print(f.read()[-3000:])
            with open(out) as f:
                got = json.load(f)
            check(r.returncode == 0 and got["code"] == 0, f"hidden, run {run}: graded")
            results = {x["exercise"]: x for x in got["results"]}
            check(all(results.get(i, {}).get("passed") for i in ids),
                  f"hidden, run {run}: full points (the spy found nothing): " +
                  "; ".join(f"{i}: {results.get(i, {}).get('reason', '')[:300]}" for i in ids
                            if not results.get(i, {}).get("passed")))
            found = sum(x.get("hidden", 0) for x in got["results"])
            check(found == count, f"hidden, run {run}: the {count} hidden cases in four doctest forms "
                                  f"are recognised as hidden ({found})")
            doc = got["gradescope"]
            shown = doc.get("output", "") + "".join(t["name"] + t["output"] for t in doc.get("tests", [])
                                                    if t["visibility"] == "visible")
            for needle in (SECRET, SECRET_INPUT, SECRET_VALUE, "step01_forms"):
                check(needle not in shown, f"hidden, run {run}: {needle!r} is not in what the student sees")
            held = {t["number"] for t in doc.get("tests", []) if t["visibility"] != "visible"}
            check(held == {"1.1", "1.4", "1.5", "1.6"},
                  f"hidden, run {run}: the exercises with hidden cases are held back: {sorted(held)}")
            visible_total = doc.get("output", "").split(" points", 1)[0]
            check(visible_total == f"{points(['1.2', '1.3'])} of {points(['1.2', '1.3'])}",
                  f"hidden, run {run}: the visible total counts only the exercises without hidden cases: "
                  f"{visible_total!r}")
    # Nothing a sandbox of the student's could read holds the hidden tests.
    leaks = []
    for base in (os.path.join(grading, "src"), os.path.join(grading, "build")):
        for d, _, names in os.walk(base):
            for n in names:
                p = os.path.join(d, n)
                if os.path.islink(p) or not os.path.isfile(p):
                    continue
                with open(p, "rb") as f:
                    if SECRET.encode() in f.read():
                        leaks.append(p)
    for n in os.listdir(grading):
        p = os.path.join(grading, n)
        if n.endswith(".log") and os.path.isfile(p):
            with open(p, "rb") as f:
                if SECRET.encode() in f.read():
                    leaks.append(p)
    check(not leaks, f"hidden: no file of the grading tree, the student's build or its logs holds a "
                     f"hidden test: {leaks[:5]}")
    judge_mode_bits = os.stat(judge_folder).st_mode & 0o777
    check(judge_mode_bits == 0o700, f"hidden: the judge's folder is the grader's only ({oct(judge_mode_bits)})")


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
    scenarios["judge-garbage"] = scenario_judge_garbage
    for name, fn in (("judge-forged", scenario_judge_forged), ("judge-exit-list", scenario_judge_exit_list),
                     ("judge-hidden", scenario_judge_hidden)):
        scenarios[name] = lambda w, fn=fn: fn(w, False)
        scenarios[name + "-fallback"] = lambda w, fn=fn: fn(w, True)
    if scenario not in scenarios:
        print(__doc__, file=sys.stderr)
        return 2
    if scenarios[scenario](work) == SKIPPED:
        return SKIPPED
    print(f"{len(failures)} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
