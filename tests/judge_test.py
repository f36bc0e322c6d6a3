#!/usr/bin/python3
"""End-to-end tests of the judge (ctest label "grading"): hostile student code against the
checker, which holds the verdicts and the expected values, and the worker, which runs the
student's code.

usage: python3 -m tests.judge_test SCENARIO WORK_DIR
  judge-garbage  student code writes frames of its own into the judge's pipe: those
                 exercises fail as a broken protocol, the others keep their points
  judge-forged, judge-exit-list, judge-hidden (and each with -fallback: without bubblewrap,
                 as root, the student's code as a user of its own; skipped, 77, when not root)
                 the judge against hostile student code: a result forged before main and an
                 exit 0 score nothing; an exit 0 inside an exercise fails it; a case list
                 filtered of hidden and failing cases changes nothing; hidden tests in
                 every doctest form are hidden and counted, and spying code (its own program run with --success, and a header
                 that breaks doctest's macros) learns nothing of
                 them that reaches what a student sees

The scenarios share the grading build of tests/grading_test.py in WORK_DIR (its helpers and
its list of failures are this file's too).
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

from tests import grading_test
from tests.grading_test import (ROOT, SKIPPED, c_string, check, exercises, hostile_tree, isolation_problem,
                                points, student_tree)

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
    scenarios = {"judge-garbage": scenario_judge_garbage}
    for name, fn in (("judge-forged", scenario_judge_forged), ("judge-exit-list", scenario_judge_exit_list),
                     ("judge-hidden", scenario_judge_hidden)):
        scenarios[name] = lambda w, fn=fn: fn(w, False)
        scenarios[name + "-fallback"] = lambda w, fn=fn: fn(w, True)
    if scenario not in scenarios:
        print(__doc__, file=sys.stderr)
        return 2
    if scenarios[scenario](work) == SKIPPED:
        return SKIPPED
    failures = grading_test.failures
    print(f"{len(failures)} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
