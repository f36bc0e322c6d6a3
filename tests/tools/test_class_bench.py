"""Unit tests of tools/grading/class_bench.py: sabotaging a solution block and comparing a
class's grades with the expected points."""
import json
import os
import tempfile
import unittest
from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools.grading import class_bench

SOURCE = """#include <a>
// EXERCISE 1.1: one (1 point)
int one() {
    // BEGIN SOLUTION
    return 1;
    // END SOLUTION
}
// EXERCISE 1.2: two (2 points)
int two() {
    // BEGIN SOLUTION
    return 2;
    // END SOLUTION
}"""


class Sabotage(unittest.TestCase):
    def test_the_line_goes_first_into_that_exercises_block(self):
        got = class_bench.insert_into_block(SOURCE, "1.2", "spin();", "#include <csignal>").split("\n")
        self.assertEqual(got[:2], ["#include <a>", "#include <csignal>"])
        at = got.index("int two() {")
        self.assertEqual(got[at + 1:at + 4], ["    // BEGIN SOLUTION", "    spin();", "    return 2;"])
        self.assertEqual(got.count("    spin();"), 1)


class Check(unittest.TestCase):
    def test_differences_and_missing_students(self):
        folder = tempfile.mkdtemp()
        with open(os.path.join(folder, "cache.json"), "w") as f:
            json.dump({"results": {
                "s00": {"rows": [{"exercise": "1.1", "points": 1}, {"exercise": "1.2", "points": 0}]},
                "s01.zip": {"rows": [{"exercise": "1.1", "points": 1}, {"exercise": "1.2", "points": 2}]}}}, f)
        expected = os.path.join(folder, "expected.json")
        with open(expected, "w") as f:
            json.dump({"s00": {"1.1": 1, "1.2": 2}, "s01": {"1.1": 1, "1.2": 2}, "s02": {"1.1": 0}}, f)
        self.assertEqual(class_bench.check(folder, expected),
                         [("s00", "1.2: 0 instead of 2"), ("s02", "no result")])


if __name__ == "__main__":
    unittest.main()
