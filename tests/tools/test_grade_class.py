"""Unit tests of tools/grading/grade_class.py: finding the submissions, the class table and
what makes a cached grade stale."""
import csv
import os
import sys
import tempfile
import unittest
import zipfile
import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from tools.grading import grade_class  # noqa: E402
from tools.grading.exercises import Exercise  # noqa: E402

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
