"""Unit tests of tools/grading/judge: the exercises' declarations read for the generated proxies
and servers, the steps a worker serves, the checker's list of cases, a case's verdict from the
checker's and the worker's ends, and the pipes between them."""
import os
import unittest
from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools import ROOT
from tools.grading import judge, sandbox
from tools.grading.exercises import CaseResult, Exercise, exercises
from tools.grading.judge import stubs


def result(status="ok", reason=None, code=0, stderr=b""):
    return sandbox.Result(status, reason or status, code, b"", stderr, 0.25)


def parse(text, exercise_id="9.1"):
    lines = text.split("\n")
    marker = next(i for i, line in enumerate(lines) if "// EXERCISE" in line)
    return stubs.parse_signature(Exercise(exercise_id, "t", 1, "steps/09_x/x.cpp", marker), text)


class Declarations(unittest.TestCase):
    def test_a_number_template(self):
        s = parse("namespace boxes {\n// EXERCISE 9.1: t (1 point)\ntemplate <typename T>\n"
                  "std::optional<Hit<T>> hit(const RayT<T>& ray, const Tri<T>& tri) {\n"
                  "    // BEGIN SOLUTION\n    return {};\n    // END SOLUTION\n}\n}\n")
        self.assertEqual((s.number_params, s.ret, s.name), (["T"], "std::optional<Hit<T>>", "hit"))
        self.assertEqual([(p.type, p.name) for p in s.params], [("const RayT<T>&", "ray"), ("const Tri<T>&", "tri")])
        self.assertEqual([v for v, _ in s.variants()], ["float", "double"])

    def test_a_const_member_and_a_mutable_one(self):
        s = parse("// EXERCISE 9.1: t (1 point)\nfloat Table::at(float x) const {\n    return x;\n}\n")
        self.assertEqual((s.cls, s.method, s.const_method), ("Table", "at", True))
        self.assertEqual(s.proxy_declaration(), "float ex_9_1(const Table& self, float x)")
        s = parse("// EXERCISE 9.1: t (1 point)\nvoid Clock::tick(double seconds) {\n}\n")
        self.assertEqual(s.proxy_declaration(), "void ex_9_1(Clock& self, double seconds)")

    def test_a_callback_needs_its_signature_in_the_table(self):
        text = ("// EXERCISE 9.1: t (1 point)\n// intersect(slot) ...\nconstexpr int kMiss = -1;\n"
                "template <typename F>\nbool any(const Bvh& bvh, F&& intersect) {\n  return false;\n}\n")
        with self.assertRaisesRegex(stubs.StubError, "intersect is a callable"):
            parse(text)
        stubs.CALLBACKS["9.1"] = {"intersect": "bool(uint32_t)"}
        try:
            s = parse(text)
        finally:
            del stubs.CALLBACKS["9.1"]
        self.assertEqual(s.number_params, [])
        self.assertEqual(s.proxy_declaration(),
                         "bool ex_9_1(const Bvh& bvh, ::boxes::judge::Callback<bool(uint32_t)> intersect)")

    def test_the_checkers_copy_calls_the_proxy_and_keeps_everything_else(self):
        text = ('#include "x.hpp"\nnamespace boxes {\nint helper() { return 1; }\n'
                "// EXERCISE 9.1: t (1 point)\ntemplate <typename T>\nT twice(T x) {\n"
                '    const char* s = "}";  // a brace in a literal\n    // BEGIN SOLUTION\n'
                "    return 2 * x;\n    // END SOLUTION\n}\nint after() { return 3; }\n}\n")
        out = stubs.checker_text(text, [parse(text)])
        self.assertIn('#include "judge/callback.hpp"', out.split("\n")[1])
        self.assertIn("namespace judge_calls {\ntemplate <typename T>\nT ex_9_1(T x);\n}", out)
        self.assertIn("T twice(T x) {\n    return ::boxes::judge_calls::ex_9_1<T>(x);\n}\nint after()", out)
        self.assertNotIn("2 * x", out)
        self.assertIn("int helper() { return 1; }", out)

    def test_the_proxies_and_the_server(self):
        s = parse("// EXERCISE 9.1: t (1 point)\ntemplate <typename T>\nbool d(float& stored, T in) {\n}\n")
        proxies = stubs.proxies_source([s], ["judge/types_core.hpp"])
        self.assertIn('return ::boxes::judge::remote<bool, decltype(stored), decltype(in)>("9.1", '
                      "::boxes::judge::variantOf<T>(), stored, in);", proxies)
        self.assertIn("template bool ex_9_1<double>(float&, double);", proxies)
        server = stubs.worker_source([s], ["judge/types_core.hpp"])
        self.assertIn("::boxes::judge::Slot<float&> a0(r);", server)
        self.assertIn("bool result = ::boxes::d<float>(a0.arg(), a1.arg());", server)
        self.assertIn('{"9.1", "double", ex_9_1_double},', server)
        self.assertIn("a0.back(w);", server)

    def test_every_exercise_of_the_workbook_is_read(self):
        sigs = judge.signatures(ROOT)
        self.assertEqual(sorted(sigs), sorted(e.id for e in exercises(ROOT)))
        for s in sigs.values():
            self.assertTrue(s.ret and s.name, s)

    def test_a_worker_serves_the_steps_its_tests_link(self):
        served = judge.served_steps(ROOT)
        for number, steps in served.items():
            self.assertIn(number, steps)
            self.assertEqual(steps, sorted(steps))
        if "06" in served:
            self.assertIn("01", served["06"])  # step 06 links step 01's triangles


class Listing(unittest.TestCase):
    def test_the_checkers_list_names_each_cases_file(self):
        xml = (b'<doctest><TestSuite><TestCase name="a" testsuite="exercise 1.1" filename="/j/src/tests/x.cpp"/>'
               b'<TestCase name="b, c" testsuite="core" filename="/j/src/tests/hidden/step01_0.cpp"/>'
               b"</TestSuite></doctest>")
        self.assertEqual(judge.listed_cases(xml), [("exercise 1.1", "a", "/j/src/tests/x.cpp"),
                                                   ("core", "b, c", "/j/src/tests/hidden/step01_0.cpp")])
        with self.assertRaises(judge.JudgeError):
            judge.listed_cases(b"\xff\xfe not xml")


class Verdicts(unittest.TestCase):
    def test_only_the_checkers_result_passes_a_case(self):
        self.assertEqual(judge.verdict(result(), result(), [CaseResult("s", "c", True)]), ("passed", ""))
        # No result from the checker: failed, whatever the worker did.
        status, reason = judge.verdict(result(), result(), [])
        self.assertEqual(status, "failed")
        self.assertIn("no test result", reason)

    def test_a_worker_that_ends_in_a_call_fails_the_case(self):
        gone = result("failed", "failed: exit 75", code=judge.WORKER_GONE,
                      stderr=b"[judge] the worker ended while exercise 1.4 ran: no result\n")
        self.assertEqual(judge.verdict(gone, result(), []),
                         ("failed", "failed: the worker ended while exercise 1.4 ran: no result (exit 0)"))
        self.assertEqual(judge.verdict(gone, result("crashed", "crashed: SIGSEGV", -11), []),
                         ("crashed", "crashed: SIGSEGV"))
        self.assertEqual(judge.verdict(gone, result("time limit"), []), ("time limit", "time limit"))
        # A passed result the checker wrote before the worker went does not count either.
        self.assertEqual(judge.verdict(gone, result(), [CaseResult("s", "c", True)])[0], "failed")

    def test_a_worker_that_breaks_the_protocol(self):
        bad = result("failed", "failed: exit 76", code=judge.WORKER_MALFORMED,
                     stderr=b"[judge] the worker's answer to exercise 1.4 breaks the protocol: a frame cut short\n")
        self.assertEqual(judge.verdict(bad, result(), []),
                         ("failed", "failed: the worker's answer to exercise 1.4 breaks the protocol: a frame cut short"))

    def test_the_worker_must_end_well_after_a_passed_case(self):
        passed = [CaseResult("s", "c", True)]
        self.assertEqual(judge.verdict(result(), result("crashed", "crashed: SIGABRT", -6), passed),
                         ("crashed", "crashed: SIGABRT"))
        self.assertEqual(judge.verdict(result(), result("failed", "failed: exit 3", 3), passed),
                         ("failed", "failed: the test passed, then its worker ended with failed: exit 3"))

    def test_a_failed_check_and_the_memory_limit(self):
        failed = [CaseResult("s", "c", False, "x.cpp:3: CHECK( a == b ) is 1 == 2")]
        self.assertEqual(judge.verdict(result("failed", "failed: exit 1", 1), result(), failed),
                         ("failed", "failed: x.cpp:3: CHECK( a == b ) is 1 == 2"))
        alloc = [CaseResult("s", "c", False, "threw: std::bad_alloc")]
        self.assertEqual(judge.verdict(result("failed", "failed: exit 1", 1), result(), alloc),
                         ("memory limit", "memory limit"))

    def test_a_limit_of_the_worker_is_the_reason_over_the_waiting_checker(self):
        self.assertEqual(judge.verdict(result("time limit"), result("time limit"), []), ("time limit", "time limit"))
        self.assertEqual(judge.verdict(result("time limit"), result(), []), ("time limit", "time limit"))
        self.assertEqual(judge.verdict(result("memory limit"), None, []), ("memory limit", "memory limit"))


class Pipes(unittest.TestCase):
    def test_each_end_gets_its_pipes_and_sees_the_other_end(self):
        def run(fds, text):
            # What sandbox.run does with pass_fds: the command owns them, this copy closes.
            for fd in fds:
                self.assertGreater(os.fstat(fd).st_size, -1)
                os.close(fd)
            return text

        checker, worker = judge.run_pair(run, run)
        self.assertRegex(checker, r"^\d+,\d+$")
        self.assertRegex(worker, r"^\d+,\d+$")
        self.assertNotEqual(checker, worker)

    def test_a_worker_runs_error_is_raised_after_the_checker(self):
        def worker(fds, text):
            for fd in fds:
                os.close(fd)
            raise sandbox.Stopped()

        def checker(fds, text):
            for fd in fds:
                os.close(fd)
            return "done"

        with self.assertRaises(sandbox.Stopped):
            judge.run_pair(checker, worker)


class LeftBehind(unittest.TestCase):
    """What a worker's user left in the shared folders (the grading without bubblewrap): found
    where that user could have made it, and nothing of anyone else touched."""

    @unittest.skipUnless(os.geteuid() == 0, "files of another user need root")
    def test_found_where_the_user_could_write(self):
        import tempfile
        uid = 59998  # no such user needed: only the files' owner
        place = tempfile.mkdtemp()
        os.chmod(place, 0o1777)

        def make(rel, folder=False, mode=None, owner=uid):
            path = os.path.join(place, rel)
            if folder:
                os.mkdir(path)
            else:
                open(path, "w").close()
            if mode is not None:
                os.chmod(path, mode)
            os.lchown(path, owner, owner)
            return path

        make("open", True, 0o777, 0)  # everyone may write: searched
        make("closed", True, 0o755, 0)  # only its owner may write: not searched...
        make("closed/open", True, 0o777, 0)  # ...but an open folder below it is
        make("closed/theirs.txt", owner=0)
        ours = [make("mine.txt"), make("mydir", True, 0o700), make("open/mine.txt"),
                make("closed/open/mine.txt")]
        open(os.path.join(place, "mydir", "inside"), "w").close()
        link = os.path.join(place, "link")
        os.symlink("/etc/hostname", link)
        os.lchown(link, uid, uid)
        ours.append(link)
        kept = [make("theirs.txt", owner=0), os.path.join(place, "closed", "theirs.txt")]

        judge._open_below_closed.pop((place,), None)
        self.assertEqual(judge.open_folders([place]), [os.path.join(place, "closed", "open")])
        self.assertEqual(judge.remove_left_behind(uid, [place]), len(ours))
        self.assertEqual([p for p in ours if os.path.lexists(p)], [], "every entry of the user is gone")
        self.assertEqual([p for p in kept if not os.path.exists(p)], [], "nobody else's entry is touched")
        self.assertTrue(os.path.exists("/etc/hostname"), "a link is removed, not followed")
        self.assertEqual(judge.remove_left_behind(uid, [place]), 0, "a second search finds nothing")


if __name__ == "__main__":
    unittest.main()
