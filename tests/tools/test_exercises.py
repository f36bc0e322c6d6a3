"""Unit tests of tools/grading/exercises.py: the exercise markers and doctest's XML results."""
import os
import tempfile
import unittest
from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools.grading import exercises
from tools.grading.exercises import case_results, parameter_names, parse_file, suite_results

SOURCE = """#include <optional>
// EXERCISE 1.4: Moller-Trumbore ray/triangle intersection (2 points)
template <typename T>
std::optional<Hit<T>> intersect(const RayT<T>& ray, const TriangleT<T>& tri, float tmax = 1.0f) {
    // BEGIN SOLUTION
    return std::nullopt;
    // END SOLUTION
}

// EXERCISE 1.5: the plane test (1 point)
int planeTest(int, const std::array<float, 3>& weights) {
    // BEGIN SOLUTION
    return 0;
    // END SOLUTION
}

// EXERCISE 1.6: no block at all (3 points)
int unfinished();
"""

PASSED = """<?xml version="1.0" encoding="UTF-8"?>
<doctest binary="t">
  <TestSuite name="exercise 1.4">
    <TestCase name="hits the middle" filename="t.cpp" line="3">
      <OverallResultsAsserts successes="2" failures="0" test_case_success="true"/>
    </TestCase>
    <TestCase name="misses" filename="t.cpp" line="9">
      <Expression success="false" type="CHECK" filename="/x/tests/t.cpp" line="11">
        <Original>hit.has_value() == false</Original>
        <Expanded>true == false</Expanded>
        <Info>ray = (0, 0, 1)</Info>
      </Expression>
      <OverallResultsAsserts successes="0" failures="1" test_case_success="false"/>
    </TestCase>
    <TestCase name="filtered" skipped="true"/>
  </TestSuite>
  <TestSuite name="exercise 1.5">
    <TestCase name="throws" filename="t.cpp" line="20">
      <Exception crash="false">exercise 1.5 is not implemented yet</Exception>
      <OverallResultsAsserts successes="0" failures="0" test_case_success="false"/>
    </TestCase>
  </TestSuite>
</doctest>
"""


class ParameterNames(unittest.TestCase):
    def test_names_follow_types(self):
        self.assertEqual(parameter_names("int f(const Ray& ray, float u, int v[3]) {"), ["ray", "u", "v"])

    def test_unnamed_parameters_and_defaults(self):
        self.assertEqual(parameter_names("void f(int, const Ray&, float t = 1.0f)"), ["t"])

    def test_template_arguments_with_commas(self):
        self.assertEqual(parameter_names("void f(const std::map<int, float>& table, Pair<A, B> p)"),
                         ["table", "p"])

    def test_no_parentheses(self):
        self.assertEqual(parameter_names("struct S {"), [])


class ParseFile(unittest.TestCase):
    def setUp(self):
        self.root = tempfile.mkdtemp()
        self.path = os.path.join(self.root, "steps", "01_x", "x.cpp")
        os.makedirs(os.path.dirname(self.path))
        with open(self.path, "w") as f:
            f.write(SOURCE)

    def test_markers_blocks_and_parameters(self):
        found = parse_file(self.path, self.root)
        self.assertEqual([(e.id, e.title, e.points) for e in found],
                         [("1.4", "Moller-Trumbore ray/triangle intersection", 2),
                          ("1.5", "the plane test", 1), ("1.6", "no block at all", 3)])
        first, second, third = found
        self.assertEqual((first.marker_line, first.begin, first.end), (1, 4, 6))
        self.assertEqual(first.parameters, ["ray", "tri", "tmax"])
        self.assertEqual(second.parameters, ["weights"])
        self.assertEqual((third.begin, third.end), (-1, -1))  # the next marker is not searched past
        self.assertEqual(first.path, os.path.join("steps", "01_x", "x.cpp"))
        self.assertEqual((first.step, first.key), (1, (1, 4)))

    def test_exercises_of_a_tree_sorted_by_number(self):
        with open(os.path.join(self.root, "steps", "01_x", "a.hpp"), "w") as f:
            f.write("// EXERCISE 1.10: later (1 point)\n// EXERCISE 1.2: earlier (4 points)\n")
        self.assertEqual([e.id for e in exercises.exercises(self.root)], ["1.2", "1.4", "1.5", "1.6", "1.10"])


class CaseResults(unittest.TestCase):
    def test_passed_failed_and_thrown(self):
        got = case_results(PASSED)
        self.assertEqual([(r.suite, r.name, r.passed) for r in got],
                         [("exercise 1.4", "hits the middle", True), ("exercise 1.4", "misses", False),
                          ("exercise 1.5", "throws", False)])
        self.assertEqual(got[0].message, "")
        self.assertEqual(got[1].message,
                         "t.cpp:11: CHECK( hit.has_value() == false ) is true == false [ray = (0, 0, 1)]")
        self.assertEqual(got[2].message, "threw: exercise 1.5 is not implemented yet")

    def test_a_file_reads_as_the_string(self):
        with tempfile.NamedTemporaryFile("w", suffix=".xml", delete=False) as f:
            f.write(PASSED)
        self.assertEqual(case_results(f.name), case_results(PASSED))

    def test_missing_results_count_as_failed(self):
        got = case_results('<doctest><TestSuite name="s"><TestCase name="c"/></TestSuite></doctest>')
        self.assertEqual([(r.name, r.passed) for r in got], [("c", False)])

    def test_unreadable_inputs_give_nothing(self):
        folder = tempfile.mkdtemp()
        fifo = os.path.join(folder, "fifo")
        os.mkfifo(fifo)  # would block a plain open()
        for bad in ("<doctest><TestSuite", '<?xml version="1.0" encoding="bogus"?><doctest/>',
                    os.path.join(folder, "missing.xml"), fifo, folder, "a\0b"):
            self.assertEqual(case_results(bad), [], bad)

    def test_oversized_input_is_refused(self):
        text = "<doctest>" + " " * exercises.MAX_RESULT_BYTES + "</doctest>"
        self.assertEqual(case_results(text), [])

    def test_suite_results_count_per_suite(self):
        out = tempfile.mkdtemp()
        for name in ("test_step01.xml", "test_step02.xml", "other.xml"):
            with open(os.path.join(out, name), "w") as f:
                f.write(PASSED)
        self.assertEqual(suite_results(out), {"exercise 1.4": (2, 2), "exercise 1.5": (0, 2)})


if __name__ == "__main__":
    unittest.main()
