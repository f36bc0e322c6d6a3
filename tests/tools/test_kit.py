"""Unit tests of tools/grading/kit.py: stripping the solutions from a source."""
import os
import tempfile
import unittest
from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools.grading import kit
from tools.grading.submissions import write_files
from tools.grading.kit import check_no_solution_left, strip_solutions

SOURCE = """#include "steps/01_x/x.hpp"
#include <cmath>

// EXERCISE 1.1: a sum (1 point)
float sum(float a, float b) {
    // BEGIN SOLUTION
    float secret = a + b;
    return secret;
    // END SOLUTION
}

// EXERCISE 1.2: a square root (2 points)
float root(float x) {
    // BEGIN SOLUTION
    return std::sqrt(x);
    // END SOLUTION
}
"""


def source_file(text):
    root = tempfile.mkdtemp()
    path = os.path.join(root, "x.cpp")
    with open(path, "w") as f:
        f.write(text)
    return path, root


class StripSolutions(unittest.TestCase):
    def test_every_block_becomes_a_stub(self):
        path, root = source_file(SOURCE)
        new, found = strip_solutions(SOURCE, path, root)
        self.assertEqual([e.id for e in found], ["1.1", "1.2"])
        self.assertEqual(new.split("\n")[:13], [
            '#include "steps/01_x/x.hpp"',
            '#include "core/exercise.hpp"',  # for NotImplemented, after the first include
            "#include <cmath>",
            "",
            "// EXERCISE 1.1: a sum (1 point)",
            "float sum(float a, float b) {",
            "    // TODO: your solution (see the step's README)",
            "    (void)a; (void)b;",
            '    throw NotImplemented("1.1");',
            "}",
            "",
            "// EXERCISE 1.2: a square root (2 points)",
            "float root(float x) {"])
        self.assertNotIn("secret", new)
        self.assertNotIn("std::sqrt", new)
        self.assertIn('throw NotImplemented("1.2");', new)
        self.assertEqual(check_no_solution_left(SOURCE, new), [])

    def test_kept_exercises_keep_their_solution(self):
        path, root = source_file(SOURCE)
        new, found = strip_solutions(SOURCE, path, root, keep={"1.2"})
        self.assertEqual([e.id for e in found], ["1.1"])
        self.assertIn("return std::sqrt(x);", new)
        self.assertNotIn("secret", new)

    def test_the_include_is_not_added_twice(self):
        text = SOURCE.replace("#include <cmath>", '#include "core/exercise.hpp"')
        path, root = source_file(text)
        new, _ = strip_solutions(text, path, root)
        self.assertEqual(new.count('#include "core/exercise.hpp"'), 1)

    def test_a_file_without_exercises_is_unchanged(self):
        text = "int f() { return 1; }\n"
        path, root = source_file(text)
        self.assertEqual(strip_solutions(text, path, root), (text, []))

    def test_an_incomplete_block_is_refused(self):
        text = SOURCE.replace("    // END SOLUTION\n}\n\n// EXERCISE 1.2", "}\n\n// EXERCISE 1.2", 1)
        path, root = source_file(text)
        with self.assertRaises(SystemExit) as e:
            strip_solutions(text, path, root)
        self.assertIn("exercise 1.1 has no complete BEGIN SOLUTION ... END SOLUTION block", str(e.exception))


class CheckNoSolutionLeft(unittest.TestCase):
    def test_a_surviving_solution_line_is_found(self):
        kit_text = SOURCE.replace("    // BEGIN SOLUTION\n", "").replace("    // END SOLUTION\n", "")
        self.assertIn("float secret = a + b;", check_no_solution_left(SOURCE, kit_text))

    def test_a_line_also_outside_the_blocks_may_stay(self):
        reference = SOURCE.replace("float root(float x) {", "float root(float x) {\n    return secret;")
        kit_text = "float root(float x) {\n    return secret;\n}"
        self.assertEqual(check_no_solution_left(reference, kit_text), [])

    def test_a_marker_left_is_found(self):
        self.assertEqual(check_no_solution_left("", "    // BEGIN SOLUTION"), ["a BEGIN/END SOLUTION marker"])


class KitContents(unittest.TestCase):
    def test_the_grader_stays_out_and_the_kits_tools_stay_in(self):
        for module in ("grade", "grade_class", "gradescope", "class_bench"):
            self.assertIn(f"tools/grading/{module}.py", kit.NOT_IN_KIT)
        for module in ("kit", "exercises", "classroom", "sandbox", "submissions", "__init__"):
            self.assertNotIn(f"tools/grading/{module}.py", kit.NOT_IN_KIT)
        self.assertIn("tests/grading_test.py", kit.NOT_IN_KIT)
        # The student's check ships in the kit (its end-to-end test, which uses the
        # solutions, does not).
        for path in ("tools/check.py", "tools/pictures.py", "tools/png.py", "tools/label.py",
                     "tests/hints/exercises.json", "tests/hints/mistakes.json"):
            self.assertNotIn(path, kit.NOT_IN_KIT)
        self.assertIn("tests/check_test.py", kit.NOT_IN_KIT)
        # The mistakes' catalogue patches the solutions: it stays out with its runner.
        self.assertIn("tools/grading/mutants.py", kit.NOT_IN_KIT)
        self.assertFalse(kit.in_kit("tests/mutants/1.4-no-v-rejection.patch"))
        self.assertIn("tools/grading/safeguards.py", kit.NOT_IN_KIT)
        self.assertFalse(kit.in_kit("tests/safeguards/offset-scales.patch"))
        self.assertTrue(kit.in_kit("tests/hints/mistakes.json"))

    def test_a_written_kit_has_no_mutant_patches(self):
        # A tree outside git (tracked_files walks it) with one exercise and one mutant.
        root = tempfile.mkdtemp()
        files = {"steps/01_x/x.cpp": SOURCE, "tests/mutants/1.1-wrong-sum.patch":
                 "Mistake: a - b\nCaught by: sum\n\n-    float secret = a + b;\n+    float secret = a - b;\n",
                 "tests/hints/mistakes.json": "{}", "tools/grading/mutants.py": "# runner\n"}
        write_files(root, files)
        dest = os.path.join(tempfile.mkdtemp(), "kit")
        kit.write_kit(dest, root)
        written = kit.tracked_files(dest)
        self.assertIn("tests/hints/mistakes.json", written)
        self.assertIn("steps/01_x/x.cpp", written)
        self.assertFalse(any(rel.startswith("tests/mutants") for rel in written), written)
        self.assertNotIn("tools/grading/mutants.py", written)
        for rel in written:
            with open(os.path.join(dest, rel)) as f:
                self.assertNotIn("secret", f.read(), rel)

    def test_tracked_files_outside_git_skip_build_output(self):
        root = tempfile.mkdtemp()
        for rel in ("a.txt", "steps/01_x/x.cpp", "build/release/x.o", "out/index.html",
                    "slides/node_modules/m.js", "tools/__pycache__/x.pyc"):
            os.makedirs(os.path.dirname(os.path.join(root, rel)) or root, exist_ok=True)
            open(os.path.join(root, rel), "w").close()
        self.assertEqual(kit.tracked_files(root), ["a.txt", "steps/01_x/x.cpp"])

    def test_a_kit_needs_a_new_folder(self):
        root = tempfile.mkdtemp()
        with self.assertRaises(SystemExit):
            kit.write_kit(root, root)
        dest = tempfile.mkdtemp()
        open(os.path.join(dest, "x"), "w").close()
        with self.assertRaises(SystemExit) as e:
            kit.write_kit(dest, root)
        self.assertIn("exists and is not empty", str(e.exception))


if __name__ == "__main__":
    unittest.main()
