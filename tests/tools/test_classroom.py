"""Unit tests of tools/grading/classroom.py: the kit's GitHub Classroom workflow."""
import unittest

from tools.grading import classroom
from tools.grading.exercises import Exercise


class Workflow(unittest.TestCase):
    def test_an_exercises_command_selects_exactly_its_suite(self):
        self.assertEqual(classroom.exercise_command("1.4", "b"),
                         "ctest --test-dir b -L '^exercise 1\\.4$' --no-tests=error --timeout 60 --output-on-failure")
        self.assertEqual(classroom.step_id("4.10"), "exercise-4-10")

    def test_yaml_quoting(self):
        self.assertEqual(classroom.quote('say "hi" \\ there'), '"say \\"hi\\" \\\\ there"')

    def test_one_step_per_exercise_worth_its_points(self):
        text = classroom.workflow([Exercise("1.1", "a sum", 1, "x"), Exercise("2.3", 'a "box"', 3, "y")])
        lines = text.split("\n")
        self.assertEqual(text.count("uses: classroom-resources/autograding-command-grader@v1"), 2)
        self.assertIn('    - name: "exercise 1.1: a sum (1 point)"', lines)
        self.assertIn('    - name: "exercise 2.3: a \\"box\\" (3 points)"', lines)
        self.assertIn("        max-score: 3", lines)
        self.assertIn('        EXERCISE-2-3_RESULTS: "${{steps.exercise-2-3.outputs.result}}"', lines)
        self.assertIn("        runners: exercise-1-1,exercise-2-3", lines)
        self.assertLess(text.index("id: exercise-1-1"), text.index("id: exercise-2-3"))


if __name__ == "__main__":
    unittest.main()
