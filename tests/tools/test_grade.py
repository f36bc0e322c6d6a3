"""Unit tests of tools/grading/grade.py and its modules (build_and_run, grade_report,
grading_tree, box): the reasons a case or a build fails, the points table and its files, the
hidden tests' names, the grading tree's sync, the deadline."""
import contextlib
import io
import json
import os
import tempfile
import time
import unittest
import xml.etree.ElementTree as ET
from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools.grading import (box, build_and_run, class_bench, errors, grade, grade_class, grade_report,
                           gradescope, grading_tree, sandbox)
from tests.tools import test_strict_numbers
from tools.grading.exercises import CaseResult, Exercise, exercises
from tools.grading.build_and_run import CaseOutcome
from tools.grading.grade_report import exercise_row


def first_step():
    return sorted({f"{e.step:02d}" for e in exercises(grade.ROOT)})[0]


def result(status="ok", reason=None, stdout=b"", stderr=b"", seconds=0.25, code=0):
    return sandbox.Result(status, reason or status, code, stdout, stderr, seconds)


class DoctestFilters(unittest.TestCase):
    # How a case ends (judge.verdict) and the checker's list of cases (judge.listed_cases):
    # tests/tools/test_judge.py.
    def test_doctest_filters_escape_commas(self):
        self.assertEqual(build_and_run.doctest_filter("a, b,c"), "a\\, b\\,c")


SRC = "/work/grade/src"


class BuildReasons(unittest.TestCase):
    def test_the_compilers_first_error(self):
        log = (f"[1/3] g++ -c {SRC}/steps/01_x/x.cpp\n"
               f"{SRC}/steps/01_x/x.cpp:12:5: warning: unused variable\n"
               f"{SRC}/steps/01_x/x.cpp:40:1: error: expected ';' before '}}' token\n"
               f"{SRC}/steps/01_x/x.cpp:41:1: error: a second one\n")
        self.assertEqual(build_and_run.first_error(log, SRC), "steps/01_x/x.cpp:40:1: error: expected ';' before '}' token")

    def test_the_linkers_error_then_ninjas_line(self):
        self.assertEqual(build_and_run.first_error("x.o: undefined reference to `f()'\n", SRC), "x.o: undefined reference to `f()'")
        self.assertEqual(build_and_run.first_error("FAILED: tests/test_step01\n", SRC), "FAILED: tests/test_step01")
        self.assertEqual(build_and_run.first_error("nothing useful\n", SRC), "the build failed")

    def test_a_limit_names_the_source_being_compiled(self):
        log = f"[2/9] g++ -O1 -c {SRC}/steps/01_x/a.cpp -o a.o\n[3/9] g++ -c {SRC}/steps/01_x/b.cpp -o b.o\n"
        self.assertEqual(build_and_run.build_reason(result("memory limit"), log, SRC),
                         "does not compile: memory limit (compiling steps/01_x/b.cpp)")
        self.assertEqual(build_and_run.build_reason(result("time limit", seconds=901.4), log, SRC),
                         "does not compile: time limit (compiling steps/01_x/b.cpp) (the build ran over 901 s)")
        self.assertEqual(build_and_run.build_reason(result("failed", "failed: exit 1"), f"{SRC}/x.cpp:1: error: no\n", SRC),
                         "does not compile: x.cpp:1: error: no")


EXERCISES = [Exercise("1.1", "a sum", 1, "steps/01_x/x.cpp"), Exercise("1.2", "a root", 2, "steps/01_x/x.cpp"),
             Exercise("1.3", "a box", 3, "steps/01_x/x.cpp"), Exercise("2.1", "a tree", 4, "steps/02_y/y.cpp")]


def table_rows():
    ok, bad = CaseOutcome("fine", "passed", "", 0.5), CaseOutcome("edge", "failed", "failed: CHECK( x )", 0.25)
    return [exercise_row(EXERCISES[0], "01", "", [ok, ok], 9.0),
            exercise_row(EXERCISES[1], "01", "", [ok, bad], 9.0),
            exercise_row(EXERCISES[2], "01", "", [], 9.0),
            exercise_row(EXERCISES[3], "02", "does not compile: y.cpp:1: error: no", [], 3.0)]


class PointsTable(unittest.TestCase):
    def test_rows(self):
        rows = table_rows()
        self.assertEqual([(r["id"], r["passed"], r["status"]) for r in rows],
                         [("1.1", True, "passed"), ("1.2", False, "failed"), ("1.3", False, "no tests"),
                          ("2.1", False, "does not compile")])
        self.assertEqual(rows[1]["message"], 'failed: CHECK( x ) (test case "edge")')
        self.assertEqual(rows[1]["details"], ["passed: fine", "FAILED: edge: failed: CHECK( x )"])
        self.assertEqual((rows[0]["seconds"], rows[3]["seconds"]), (1.0, 3.0))  # cases' time, else the step's
        self.assertEqual(rows[2]["reason"], "no test cases for this exercise")
        start = exercise_row(EXERCISES[0], "01", ("time limit", "time limit (the test program does not list its tests)"), [], 1.0)
        self.assertEqual((start["status"], start["case"]), ("time limit", ""))
        long = exercise_row(EXERCISES[0], "01", "does not compile: " + "x" * 600, [], 1.0)
        self.assertEqual((len(long["reason"]), long["reason"][-3:]), (500, "..."))

    def test_the_printed_table(self):
        with tempfile.TemporaryFile("w+") as out:
            self.assertEqual(grade_report.print_table(table_rows(), ["a note"], out), (1, 10))
            out.seek(0)
            text = out.read()
        self.assertEqual(text.split("\n"), [
            "", "Grade: 1 of 10 points", "",
            "exercise  points  result  why it failed",
            "1.1        1 / 1   passed  ",
            '1.2        0 / 2   FAILED  failed: CHECK( x ) (test case "edge")',
            "1.3        0 / 3   FAILED  no test cases for this exercise",
            "2.1        0 / 4   FAILED  does not compile: y.cpp:1: error: no",
            "note: a note", ""])

    def test_json_and_junit_files(self):
        folder = tempfile.mkdtemp()
        rows = table_rows()
        grade_report.write_json(os.path.join(folder, "g.json"), rows, ["n"], 12.345)
        with open(os.path.join(folder, "g.json")) as f:
            doc = json.load(f)
        self.assertEqual((doc["points"], doc["max"], doc["seconds"], doc["notes"]), (1, 10, 12.35, ["n"]))
        self.assertEqual(doc["exercises"][1], {"exercise": "1.2", "title": "a root", "step": "01", "points": 0,
                                               "max": 2, "status": "failed", "reason": "failed: CHECK( x )",
                                               "case": "edge", "details": ["passed: fine", "FAILED: edge: failed: CHECK( x )"],
                                               "hidden": 0, "seconds": 0.75})
        grade_report.write_junit(os.path.join(folder, "g.xml"), rows, ["n"], 12.3)
        root = ET.parse(os.path.join(folder, "g.xml")).getroot()
        self.assertEqual((root.get("tests"), root.get("failures")), ("4", "3"))
        step1 = root.find("testsuite[@name='step 01']")
        self.assertEqual({p.get("name"): p.get("value") for p in step1.iter("property")},
                         {"points": "1", "points_possible": "6"})
        names = [c.get("name") for c in root.iter("testcase")]
        self.assertEqual(names[0], "exercise 1.1: a sum (1 point)")
        self.assertEqual(names[1], "exercise 1.2: a root (2 points)")
        failure = root.find(".//testcase[@classname='exercise 1.2']/failure")
        self.assertEqual(failure.get("message"), 'failed: CHECK( x ) (test case "edge")')

    def test_results_by_exercise(self):
        got = grade_report.results_by_exercise(table_rows())
        self.assertEqual(got[0], {"exercise": "1.1", "title": "a sum", "step": "01", "max": 1, "passed": True,
                                  "points": 1, "status": "passed", "reason": "", "seconds": 1.0,
                                  "details": ["passed: fine", "passed: fine"], "hidden": 0,
                                  "public_details": ["passed: fine", "passed: fine"], "public_passed": True})
        self.assertEqual((got[1]["points"], got[1]["reason"]), (0, "edge: failed: CHECK( x )"))
        self.assertEqual(got[3]["details"], ["does not compile: y.cpp:1: error: no"])


class StudentText(unittest.TestCase):
    HOSTILE = "a\x1b[31mred\x00\x07\x0b\x0c\r\x7f\x85\ufffe\uffff\ud800 tab\tnewline\n\u00e9"

    def test_what_xml_forbids_and_terminals_obey_is_written_out(self):
        self.assertEqual(grade_report.printable(self.HOSTILE),
                         "a\\x1b[31mred\\x00\\x07\\x0b\\x0c\\x0d\\x7f\\x85\\ufffe\\uffff\\ud800 tab\tnewline\n\u00e9")

    def test_the_reports_stay_well_formed(self):
        e = Exercise("1.1", "a sum", 1, "steps/01_x/x.cpp", 1, 0, 0)
        o = CaseOutcome("edge " + self.HOSTILE, "failed", "failed: threw: " + self.HOSTILE, 0.5)
        rows = [exercise_row(e, "01", "", [o], 0.5)]
        folder = tempfile.mkdtemp()
        grade_report.write_junit(os.path.join(folder, "g.xml"), rows, ["note " + self.HOSTILE], 1.0)
        root = ET.parse(os.path.join(folder, "g.xml")).getroot()  # raises when not well-formed
        failure = root.find(".//failure")
        self.assertIn("\\x1b[31mred", failure.get("message"))
        self.assertIn("\\x00", failure.text)
        grade_report.write_json(os.path.join(folder, "g.json"), rows, ["note " + self.HOSTILE], 1.0)
        with open(os.path.join(folder, "g.json"), encoding="utf-8") as f:
            doc = json.load(f)
        self.assertNotRegex(doc["exercises"][0]["reason"], "[\x00-\x08\x0b-\x1f\x7f\ufffe\ud800]")


class GradingTree(unittest.TestCase):
    def test_hidden_test_names(self):
        hidden = tempfile.mkdtemp()
        for name in ("step01_extra.cpp", "test_step02.cpp", "notes.txt"):
            open(os.path.join(hidden, name), "w").close()
        self.assertEqual(grading_tree.hidden_tests(hidden, {"01", "02"}),
                         {"01": ["step01_extra.cpp"], "02": ["test_step02.cpp"]})
        self.assertEqual(grading_tree.hidden_tests(None, {"01"}), {})
        open(os.path.join(hidden, "step07.cpp"), "w").close()
        with self.assertRaisesRegex(errors.GradeError, "hidden test step07.cpp: name it stepNN"):
            grading_tree.hidden_tests(hidden, {"01", "02"})
        with self.assertRaisesRegex(errors.GradeError, "no such folder"):
            grading_tree.hidden_tests(os.path.join(hidden, "missing"), {"01"})

    def test_sync_keeps_unchanged_files_and_removes_others(self):
        dest = tempfile.mkdtemp()
        grading_tree.sync_tree(dest, {"a/x.cpp": b"1", "a/y.cpp": b"2", "b/z.cpp": b"3"})
        old = os.path.join(dest, "a", "x.cpp")
        os.utime(old, (1, 1))
        grading_tree.sync_tree(dest, {"a/x.cpp": b"1", "a/y.cpp": b"changed"})
        self.assertEqual(os.stat(old).st_mtime, 1)  # unchanged: not written, so not rebuilt
        with open(os.path.join(dest, "a", "y.cpp"), "rb") as f:
            self.assertEqual(f.read(), b"changed")
        self.assertFalse(os.path.exists(os.path.join(dest, "b")))

    def test_student_code_sees_no_secrets(self):
        os.environ["BOXES_SECRET_TOKEN"] = "x"
        env = box.clean_env("/box")
        self.assertNotIn("BOXES_SECRET_TOKEN", env)
        self.assertEqual((env["HOME"], env["TMPDIR"], env["MALLOC_ARENA_MAX"]), ("/box", "/tmp", "2"))
        self.assertLessEqual(set(env), {"PATH", "LANG", "LC_ALL", "CC", "CXX", "TZ", "HOME", "TMPDIR", "MALLOC_ARENA_MAX"})


class Deadline(unittest.TestCase):
    def setUp(self):
        self.real = sandbox.run
        self.calls = []

        def fake(cmd, limits, **kw):
            self.calls.append(limits.seconds)
            return result()
        sandbox.run = fake

    def tearDown(self):
        sandbox.run = self.real

    def test_a_run_gets_the_time_left(self):
        iso = box.Isolation(False, sandbox.Limits(900), sandbox.Limits(60), deadline=time.monotonic() + 30)
        box.sandboxed(["x"], iso.test, iso)
        self.assertTrue(29 < self.calls[0] <= 30, self.calls)
        box.sandboxed(["x"], sandbox.Limits(5), iso)
        self.assertEqual(self.calls[1], 5)

    def test_no_time_left(self):
        iso = box.Isolation(False, sandbox.Limits(900), sandbox.Limits(60), deadline=time.monotonic() - 1)
        with self.assertRaises(errors.OutOfTime):
            box.sandboxed(["x"], iso.test, iso)
        self.assertEqual(self.calls, [])

    def test_no_deadline(self):
        iso = box.Isolation(False, sandbox.Limits(900), sandbox.Limits(60))
        box.sandboxed(["x"], iso.test, iso)
        self.assertEqual(self.calls, [60])


class GradeInto(unittest.TestCase):
    def test_a_tree_that_cannot_be_graded_is_a_report(self):
        folder = tempfile.mkdtemp()
        r = grade.grade_into(folder, tempfile.mkdtemp(), grade.GradeOptions(no_isolation=True))
        self.assertEqual((r.code, r.results), (1, []))
        self.assertTrue(r.last_line.startswith("grade: ") and r.last_line.endswith("has no steps/ folder: is it a workbook tree?"),
                        r.last_line)
        self.assertEqual(sorted(os.listdir(folder)), ["grade.log", "points.txt"])

    def test_an_unknown_step(self):
        tree = tempfile.mkdtemp()
        os.makedirs(os.path.join(tree, "steps"))
        r = grade.grade_into(tempfile.mkdtemp(), tree, grade.GradeOptions(steps=["99"], no_isolation=True))
        self.assertEqual(r.code, 1)
        self.assertIn("grade: --steps 99: no such step with exercises", r.last_line)


class FullDisk(unittest.TestCase):
    """A full grading disk is the machine's failure: no points, a reason, exit 75."""

    def setUp(self):
        self.tree = tempfile.mkdtemp()
        os.makedirs(os.path.join(self.tree, "steps"))
        os.environ["BOXES_GRADE_MIN_FREE_MB"] = str(1 << 40)  # more than any disk has

    def tearDown(self):
        del os.environ["BOXES_GRADE_MIN_FREE_MB"]

    def test_the_free_space_it_needs(self):
        self.assertIn("the grading disk is full", box.disk_trouble(self.tree))
        os.environ["BOXES_GRADE_MIN_FREE_MB"] = "1"
        self.assertIsNone(box.disk_trouble(self.tree))

    def test_grading_stops_before_it_starts(self):
        folder = tempfile.mkdtemp()
        r = grade.grade_into(folder, self.tree, grade.GradeOptions(no_isolation=True, steps=[first_step()],
                                                                   work=tempfile.mkdtemp()))
        self.assertEqual((r.code, r.results), (errors.NOT_GRADED_EXIT, []))
        self.assertTrue(r.last_line.startswith("not graded: the grading disk is full"), r.last_line)
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            code = grade.main([self.tree, "--no-isolation", "--steps", first_step(), "--work", tempfile.mkdtemp()])
        self.assertEqual(code, errors.NOT_GRADED_EXIT)
        self.assertIn("grade: not graded: the grading disk is full", err.getvalue())

    def test_a_failed_command_on_a_full_disk(self):
        real = sandbox.run
        sandbox.run = lambda cmd, limits, **kw: result("failed", "failed: exit 1")
        try:
            iso = box.Isolation(False, sandbox.Limits(900), sandbox.Limits(60), disk=self.tree)
            with self.assertRaisesRegex(errors.NotGraded, "the grading disk is full"):
                box.sandboxed(["x"], iso.test, iso)
            os.environ["BOXES_GRADE_MIN_FREE_MB"] = "1"
            self.assertEqual(box.sandboxed(["x"], iso.test, iso).status, "failed")  # the student's
        finally:
            sandbox.run = real


class StrictNumbers(test_strict_numbers.FlagChecks, unittest.TestCase):
    """Every number on the grader's command lines: an overflowing, a fractional and a
    trailing-junk value refused with one line naming the flag and the value."""

    def test_grade(self):
        for flag in ("--memory", "--build-memory", "--jobs"):
            self.check(grade.main, ["tree"], flag, self.BAD_INTEGERS)
        for flag in ("--timeout", "--output", "--build-timeout"):
            self.check(grade.main, ["tree"], flag, self.BAD_DECIMALS)
        self.check(grade.main, ["tree"], "--steps", ("999", "1.5", "01x"))

    def test_grade_class(self):
        self.check(grade_class.main, ["subs"], "--jobs", self.BAD_INTEGERS)
        for flag in ("--timeout", "--student-timeout"):
            self.check(grade_class.main, ["subs"], flag, self.BAD_DECIMALS)
        self.check(grade_class.main, ["subs"], "--steps", ("999", "1.5", "01x"))

    def test_gradescope_bundle(self):
        for flag in ("--timeout", "--limit"):
            self.check(gradescope.main, ["bundle", "a.zip"], flag, self.BAD_DECIMALS)
        self.check(gradescope.main, ["bundle", "a.zip"], "--steps", ("999", "1.5", "01x"))

    def test_class_bench(self):
        for flag in ("--students", "--seed", "--jobs"):
            self.check(class_bench.main, ["bench"], flag, self.BAD_INTEGERS)
        self.check(class_bench.main, ["bench"], "--jobs", ("1,99999999999999999999999", "1,2.5", "1,2x"))
        self.check(class_bench.main, ["bench"], "--timeout", self.BAD_DECIMALS)
        for flag in ("--students", "--seed"):
            self.check(class_bench.main, ["make", "dest"], flag, self.BAD_INTEGERS)


if __name__ == "__main__":
    unittest.main()
