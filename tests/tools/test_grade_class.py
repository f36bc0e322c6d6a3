"""Unit tests of tools/grading/grade_class.py: finding the submissions, the class table (its
names escaped), one bad submission's row and what makes a cached grade stale."""
import contextlib
import csv
import io
import os
import tempfile
import types
import unittest
import zipfile
from unittest import mock
from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools.grading import grade, grade_class
from tools.grading.errors import NOT_GRADED_EXIT
from tools.grading.exercises import Exercise

EXERCISES = [Exercise("1.1", "a sum", 1, "x"), Exercise("1.2", "a root", 2, "x")]


class Discover(unittest.TestCase):
    def test_folders_and_archives_by_name(self):
        folder = tempfile.mkdtemp()
        for name in ("alice", "bob.zip", "carol.tar.gz", ".hidden", "dave"):
            if name.endswith(".zip"):
                zipfile.ZipFile(os.path.join(folder, name), "w").close()
            elif name.endswith(".gz"):
                open(os.path.join(folder, name), "w").close()
            else:
                os.mkdir(os.path.join(folder, name))
        open(os.path.join(folder, "notes.txt"), "w").close()
        os.mkdir(os.path.join(folder, "dave.zip"))  # a folder named like an archive of dave
        got = grade_class.discover(folder)
        self.assertEqual([(s["student"], s["entry"]) for s in got],
                         [("alice", "alice"), ("bob", "bob.zip"), ("carol", "carol.tar.gz"),
                          ("dave", "dave"), ("dave.zip", "dave.zip")])  # a second "dave" keeps its entry's name


class ClassTable(unittest.TestCase):
    def test_one_row_per_student_sorted(self):
        results = [{"student": "bob", "rows": [{"exercise": "1.2", "points": 2}], "total": 2, "build": "ok",
                    "seconds": 12.34},
                   {"student": "alice", "rows": [], "total": 0, "build": "not graded: no step sources"}]
        path = os.path.join(tempfile.mkdtemp(), "class.csv")
        grade_class.write_csv(path, results, EXERCISES)
        with open(path) as f:
            rows = list(csv.reader(f))
        self.assertEqual(rows, [["student", "1.1", "1.2", "total", "max", "build", "seconds"],
                                ["alice", "0", "0", "0", "3", "not graded: no step sources", "0.0"],
                                ["bob", "0", "2", "2", "3", "ok", "12.3"]])
        self.assertFalse(os.path.exists(path + ".tmp"))


class HostileNames(unittest.TestCase):
    NAMES = ["\x1b]0;owned\x07\x1b[2J", "new\nline", "=HYPERLINK(\"http://x\")", "+1", "-2", "@SUM(A1)",
             "\u202egnp.exe", "tab\there"]

    def test_a_cell_is_one_escaped_line_and_never_a_formula(self):
        for name in self.NAMES:
            got = grade_class.cell(name)
            self.assertFalse(any(c in got for c in "\x1b\x07\n\t\u202e"), got)
            self.assertNotIn(got[:1], ("=", "+", "-", "@"), got)
        self.assertEqual(grade_class.cell("\x1b[31mred"), "\\x1b[31mred")
        self.assertEqual(grade_class.cell("=1+1"), "'=1+1")
        self.assertEqual(grade_class.cell("alice"), "alice")

    def test_the_table_and_the_progress_lines_carry_names_escaped(self):
        results = [{"student": n, "rows": [], "total": 0, "build": f"not graded: {n}"} for n in self.NAMES]
        path = os.path.join(tempfile.mkdtemp(), "class.csv")
        grade_class.write_csv(path, results, EXERCISES)
        with open(path, newline="") as f:
            text = f.read()
        self.assertFalse(any(c in text for c in "\x1b\x07\t\u202e"))
        self.assertEqual(len(text.splitlines()), 1 + len(self.NAMES))  # no name adds a line
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            grade_class.say("1/1 graded: " + self.NAMES[0] + self.NAMES[1])
        self.assertEqual(err.getvalue(), "[class] 1/1 graded: \\x1b]0;owned\\x07\\x1b[2Jnew\\nline\n")


class OneBadSubmission(unittest.TestCase):
    """What goes wrong with one submission is its own row; the class goes on."""

    def setUp(self):
        self.root = tempfile.mkdtemp()
        self.workers = grade_class.Workers(os.path.join(self.root, "work"), 1)
        self.opts = types.SimpleNamespace(out=self.root, steps=["01"], hidden=None, timeout=10, compile_jobs=1,
                                          no_sandbox=True, student_timeout=60)

    def tearDown(self):
        self.workers.close()

    def grade(self, files):
        sub = {"student": "s", "entry": "s", "hash": "h", "files": files}
        with contextlib.redirect_stderr(io.StringIO()):
            return grade_class.grade_one(sub, self.workers, self.opts)

    def test_staging_that_fails_is_a_not_graded_row(self):
        # Paths the reader would refuse (submissions.check_paths), given to staging directly.
        r = self.grade({"steps/01_x/a.cpp": b"1", "steps/01_x/a.cpp/b.cpp": b"2"})
        self.assertEqual((r["status"], r["total"], r["rows"]), ("error", 0, []))
        self.assertTrue(r["build"].startswith("not graded: staging failed") and r["build"].endswith(", retry"),
                        r["build"])
        self.assertEqual(self.workers.take(), 0)  # the worker's folder was given back
        self.workers.give(0)

    def test_a_failure_of_the_grader_is_a_not_graded_row(self):
        with mock.patch.object(grade_class, "run_grader", side_effect=RuntimeError("a bug")):
            r = self.grade({"steps/01_x/a.cpp": b"1"})
        self.assertEqual(r["build"], "not graded: the grader failed (RuntimeError: a bug), retry")

    def test_a_full_grading_disk_is_a_not_graded_row(self):
        report = grade.Report(NOT_GRADED_EXIT, 1.0, [], [], "not graded: the grading disk is full: 3 MB free")
        with mock.patch.object(grade_class, "run_grader", return_value=report):
            r = self.grade({"steps/01_x/a.cpp": b"1"})
        self.assertEqual((r["status"], r["build"]),
                         ("error", "not graded: the grading disk is full: 3 MB free, retry"))


class ConfigHash(unittest.TestCase):
    def test_options_and_hidden_tests_change_it(self):
        base = grade_class.config_hash(None, ["01"], 60.0)
        self.assertEqual(base, grade_class.config_hash(None, ["01"], 60.0))
        self.assertNotEqual(base, grade_class.config_hash(None, ["02"], 60.0))
        self.assertNotEqual(base, grade_class.config_hash(None, ["01"], 30.0))
        hidden = tempfile.mkdtemp()
        with open(os.path.join(hidden, "step01_h.cpp"), "w") as f:
            f.write("one")
        first = grade_class.config_hash(hidden, ["01"], 60.0)
        self.assertNotEqual(base, first)
        with open(os.path.join(hidden, "step01_h.cpp"), "w") as f:
            f.write("two")
        self.assertNotEqual(first, grade_class.config_hash(hidden, ["01"], 60.0))

    def test_what_decides_a_grade(self):
        self.assertTrue(all(os.path.exists(os.path.join(grade_class.ROOT, p)) or
                            os.path.exists(os.path.join(grade_class.ROOT, p + ".py"))
                            for p in grade_class.GRADER_FILES), grade_class.GRADER_FILES)


class Workers(unittest.TestCase):
    def test_folders_are_handed_out_and_back(self):
        root = tempfile.mkdtemp()
        w = grade_class.Workers(root, 2)
        try:
            self.assertEqual((w.take(), w.take()), (0, 1))
            w.give(1)
            self.assertEqual(w.take(), 1)
            self.assertTrue(os.path.exists(os.path.join(root, "w0", "lock")))
        finally:
            w.close()


if __name__ == "__main__":
    unittest.main()
