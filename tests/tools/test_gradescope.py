"""Unit tests of tools/grading/gradescope.py: results.json in Gradescope's format and the
hidden tests' names."""
import os
import tempfile
import unittest
from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools.grading import gradescope

# The grader's rows say how many of an exercise's cases are hidden tests (from the checker's own
# list: whatever doctest form declared them) and give the other cases' details apart.
ROWS = [{"exercise": "1.1", "title": "a sum", "max": 1, "points": 1, "passed": True, "status": "passed",
         "reason": "", "details": ["passed: fine", "passed: one more"], "hidden": 1,
         "public_details": ["passed: fine"], "public_passed": True},
        {"exercise": "1.2", "title": "a root", "max": 2, "points": 0, "passed": False, "status": "time limit",
         "reason": "slow: time limit", "details": ["FAILED: slow: time limit"], "hidden": 0,
         "public_details": ["FAILED: slow: time limit"], "public_passed": False}]
CONFIG = {"steps": ["01"], "hidden_visibility": "after_due_date", "hidden_cases": {"1.1": ["hidden: one more"]}}


class ResultsJson(unittest.TestCase):
    def test_one_test_per_exercise_and_a_public_one_beside_hidden_tests(self):
        doc = gradescope.results_json(ROWS, CONFIG, ["a note"], 41.6)
        self.assertEqual((doc["score"], doc["execution_time"], doc["stdout_visibility"]), (1, 42, "hidden"))
        # What students always see counts only the exercise without hidden tests.
        self.assertTrue(doc["output"].startswith("0 of 2 points from the exercises without hidden tests "
                                                 "(steps 01). Exercises 1.1 also have hidden tests: their "
                                                 "points show after the due date."), doc["output"])
        self.assertNotIn("1 of", doc["output"])
        self.assertTrue(doc["output"].endswith("note: a note\n"))
        # Plain text: the output holds what the student's code printed and their file names.
        self.assertEqual((doc["output_format"], doc["test_output_format"], doc["test_name_format"]),
                         ("text", "text", "text"))
        tests = doc["tests"]
        self.assertEqual([(t["number"], t["score"], t["max_score"], t["status"], t["visibility"]) for t in tests],
                         [("1.1", 1, 1, "passed", "after_due_date"), ("1.1.0", 0, 0, "passed", "visible"),
                          ("1.2", 0, 2, "failed", "visible")])
        self.assertEqual(tests[1]["output"], "passed: fine")  # the hidden case is not shown
        self.assertNotIn("one more", "".join(t["output"] for t in tests if t["visibility"] == "visible"))
        self.assertEqual(tests[2]["output"].split("\n"),
                         ["0 of 2 points: time limit", "first failure: slow: time limit", "FAILED: slow: time limit"])
        self.assertEqual(tests[0]["name"], "exercise 1.1: a sum")

    def test_without_hidden_tests_the_total(self):
        doc = gradescope.results_json([dict(r, hidden=0) for r in ROWS], dict(CONFIG, hidden_cases={}), [], 3)
        self.assertTrue(doc["output"].startswith("1 of 3 points (steps 01). Each exercise"), doc["output"])
        self.assertEqual([t["visibility"] for t in doc["tests"]], ["visible", "visible"])

    def test_a_failure_is_zero_points_and_a_message(self):
        doc = gradescope.failure(gradescope.GRADER_FAILED)
        self.assertEqual((doc["score"], doc["tests"], doc["output_format"]), (0, [], "text"))
        self.assertIn("not a verdict on your code", doc["output"])

    def test_hidden_case_names_per_exercise(self):
        hidden = tempfile.mkdtemp()
        with open(os.path.join(hidden, "step01_h.cpp"), "w") as f:
            f.write('TEST_SUITE("exercise 1.1") {\n TEST_CASE("one") {}\n TEST_CASE("two") {}\n}\n'
                    'TEST_SUITE("core") { TEST_CASE("not counted") {} }\n'
                    'TEST_SUITE("exercise 1.3") { TEST_CASE("three") {} }\n')
        with open(os.path.join(hidden, "notes.txt"), "w") as f:
            f.write('TEST_SUITE("exercise 9.9") { TEST_CASE("no") {} }')
        self.assertEqual(gradescope.hidden_case_names(hidden), {"1.1": ["one", "two"], "1.3": ["three"]})


if __name__ == "__main__":
    unittest.main()
