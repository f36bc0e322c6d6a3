"""Tests of tools/grading/mutants.py: the catalogue of students' mistakes (tests/mutants) is
sound (every patch applies to the reference, names its test case, and has that case's hint),
and the runner's pieces work on a small tree. The same for the catalogue of the hard cases'
safeguards (tests/safeguards, tools/grading/safeguards.py): every patch applies and names
test cases that exist. The slow runs themselves are the ctest label mutants and
./workbook mutants --safeguards."""
import json
import os
import tempfile
import unittest

from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)
from tools import ROOT
from tools.grading import mutants, safeguards
from tools.grading.submissions import write_files

PATCH = """Mistake: a + b written a - b
Caught by: sum: worked values

diff --git a/steps/01_x/x.cpp b/steps/01_x/x.cpp
--- a/steps/01_x/x.cpp
+++ b/steps/01_x/x.cpp
@@ -1,3 +1,3 @@
 float sum(float a, float b) {
-    return a + b;
+    return a - b;
 }
"""
SOURCE = "float sum(float a, float b) {\n    return a + b;\n}\n"
TESTS = 'TEST_SUITE("exercise 1.1") {\n    TEST_CASE("sum: worked values") {}\n}\n'


def small_tree(patch=PATCH, hints=None):
    root = tempfile.mkdtemp()
    files = {"steps/01_x/x.cpp": SOURCE, "tests/step01_x.cpp": TESTS,
             "tests/mutants/1.1-minus.patch": patch,
             "tests/hints/mistakes.json": json.dumps(
                 hints if hints is not None else
                 {"sum: worked values": {"exercise": "1.1", "hint": "a sum adds"}})}
    write_files(root, files)
    return root


class TheCatalogue(unittest.TestCase):
    def test_every_patch_applies_names_its_case_and_has_its_hint(self):
        problems = mutants.check_catalogue(ROOT)
        self.assertEqual(problems, [], "\n".join(problems))

    def test_every_exercise_has_at_least_two_mistakes(self):
        from tools.grading.exercises import exercises
        counts = {}
        for m in mutants.catalogue(ROOT):
            counts[m.exercise] = counts.get(m.exercise, 0) + 1
        few = [e.id for e in exercises(ROOT) if counts.get(e.id, 0) < 2]
        self.assertEqual(few, [], "exercises with fewer than two catalogued mistakes")

    def test_the_three_the_audit_missed_are_catalogued(self):
        ids = {m.id for m in mutants.catalogue(ROOT)}
        for wanted in ("1.4-no-v-rejection", "1.5-no-double-fallback", "4.4-children-against-tmax"):
            self.assertIn(wanted, ids)


class Pieces(unittest.TestCase):
    def test_the_header_is_read(self):
        root = small_tree()
        [m] = mutants.catalogue(root)
        self.assertEqual((m.id, m.exercise, m.step), ("1.1-minus", "1.1", 1))
        self.assertEqual(m.mistake, "a + b written a - b")
        self.assertEqual(m.caught_by, "sum: worked values")
        self.assertEqual(mutants.check_catalogue(root), [])

    def test_a_stale_patch_a_missing_hint_and_an_unknown_case_are_problems(self):
        root = small_tree(PATCH.replace("return a + b", "return a * b"), hints={})
        problems = mutants.check_catalogue(root)
        self.assertTrue(any("does not apply" in p for p in problems), problems)
        self.assertTrue(any("no hint" in p for p in problems), problems)
        root = small_tree(PATCH.replace("Caught by: sum: worked values", "Caught by: no such case"))
        problems = mutants.check_catalogue(root)
        self.assertTrue(any("no test case named 'no such case'" in p for p in problems), problems)

    def test_apply_and_revert_in_a_copy_leave_the_reference(self):
        root = small_tree()
        tree = os.path.join(tempfile.mkdtemp(), "tree")
        mutants.sync_tree(root, tree)
        path = os.path.join(tree, "steps/01_x/x.cpp")
        m = mutants.catalogue(root)[0]
        self.assertEqual(mutants.git_apply(tree, m.path).returncode, 0)
        with open(path) as f:
            self.assertIn("a - b", f.read())
        self.assertEqual(mutants.git_apply(tree, m.path, "-R").returncode, 0)
        with open(path) as f:
            self.assertEqual(f.read(), SOURCE)
        # A second sync keeps unchanged files' times (the build stays incremental).
        before = os.stat(os.path.join(tree, "tests/step01_x.cpp")).st_mtime_ns
        mutants.sync_tree(root, tree)
        self.assertEqual(os.stat(os.path.join(tree, "tests/step01_x.cpp")).st_mtime_ns, before)

    def test_select_by_exercise_step_or_name(self):
        root = small_tree()
        all_ = mutants.catalogue(root)
        self.assertEqual(mutants.select(all_, ["1.1"]), all_)
        self.assertEqual(mutants.select(all_, ["01"]), all_)
        self.assertEqual(mutants.select(all_, ["1.1-minus"]), all_)
        with self.assertRaises(SystemExit):
            mutants.select(all_, ["9.9"])

    def test_the_table(self):
        text = mutants.table([("1.4-no-v-rejection", "1.4", "caught", ["a case"]),
                              ("4.4-x", "4.4", "MISSED", [])])
        lines = text.split("\n")
        self.assertTrue(lines[0].startswith("mutant"))
        self.assertIn("caught", lines[1])
        self.assertIn("a case", lines[1])
        self.assertTrue(lines[2].rstrip().endswith("-"))


SAFEGUARD = """Safeguard: a sum adds
Caught by: hard case: sums

diff --git a/steps/01_x/x.cpp b/steps/01_x/x.cpp
--- a/steps/01_x/x.cpp
+++ b/steps/01_x/x.cpp
@@ -1,3 +1,3 @@
 float sum(float a, float b) {
-    return a + b;
+    return a - b;
 }
"""


def safeguard_tree(patch=SAFEGUARD, tests=None):
    root = small_tree()
    files = {"tests/safeguards/sum-adds.patch": patch,
             "tests/step01_x.cpp": tests or 'TEST_CASE("hard case: sums") {}\n',
             "tests/hard_cases.cpp": 'TEST_CASE("hard case: far") {}\n'}
    write_files(root, files)
    return root


class TheSafeguards(unittest.TestCase):
    def test_every_patch_applies_and_names_cases_that_exist(self):
        problems = safeguards.check_catalogue(ROOT)
        self.assertEqual(problems, [], "\n".join(problems))

    def test_the_catalogue_covers_the_named_hard_cases_and_the_analysis(self):
        cases = {c.split(": ", 1)[-1] if c.startswith("test_") else c
                 for s in safeguards.catalogue(ROOT) for c in s.caught_by}
        for wanted in ("hard case: a triangle 1e21 across straight ahead is hit",
                       "hard case: grazing rays nearly parallel to a triangle hit it where double does",
                       "hard case: no self-intersection acne on spheres at scene scales 1 to 1e5",
                       "hard case: no self-intersection acne on meshes at scene scales 1 to 1e5",
                       "hard case: light does not leak through a closed thin wall at scales 1 to 1e5",
                       "hard case: spheres 1e4 and 1e5 from the origin are hit and missed as in double",
                       "hard case: a ray touching a sphere tangentially hits it once at the tangent point",
                       "hard case: a ray starting on a sphere finds the far side or nothing",
                       "effects on demand: 200 random scenes bit-identical with fewer or equal rays"):
            self.assertIn(wanted, cases)
        tmin = [c for c in cases if "t == tmin" in c]
        self.assertGreaterEqual(len(tmin), 4, tmin)  # triangles, spheres and planes, boxes, slabs

    def test_the_header_and_the_programs(self):
        root = safeguard_tree()
        [s] = safeguards.catalogue(root)
        self.assertEqual((s.id, s.safeguard, s.caught_by), ("sum-adds", "a sum adds", ["hard case: sums"]))
        self.assertEqual(safeguards.check_catalogue(root), [])
        where = safeguards.case_programs(root)
        self.assertEqual(where["hard case: sums"], {"test_step01"})
        self.assertEqual(where["hard case: far"], {"test_core"})
        self.assertEqual(safeguards.named_cases(s, where), [("test_step01", "hard case: sums")])

    def test_a_stale_patch_an_unknown_and_an_ambiguous_case_are_problems(self):
        root = safeguard_tree(SAFEGUARD.replace("return a + b", "return a * b"))
        self.assertTrue(any("does not apply" in p for p in safeguards.check_catalogue(root)))
        root = safeguard_tree(SAFEGUARD.replace("Caught by: hard case: sums", "Caught by: no such case"))
        self.assertIn("sum-adds: no test case named 'no such case'", safeguards.check_catalogue(root))
        both = 'TEST_CASE("hard case: far") {}\n'
        root = safeguard_tree(SAFEGUARD.replace("hard case: sums", "hard case: far"), both)
        self.assertTrue(any("name its program" in p for p in safeguards.check_catalogue(root)))
        # Named with its program, the shared name is no problem.
        root = safeguard_tree(SAFEGUARD.replace("hard case: sums", "test_core: hard case: far"), both)
        self.assertEqual(safeguards.check_catalogue(root), [])

    def test_the_tests_run_and_the_verdict(self):
        listed = {"test_step01: hard case: sums": 1, "test_step01: other": 2,
                  "test_step01: effects: random": 3, "test_core: hard case: far": 4}
        named = [("test_step01", "effects: random")]
        self.assertEqual(safeguards.chosen_tests(listed, named),
                         {"test_step01: hard case: sums": 1, "test_step01: effects: random": 3})
        self.assertEqual(safeguards.verdict(named, "failed", ["test_step01: effects: random"]), "proven")
        self.assertEqual(safeguards.verdict(named, "passed", []), "MISSED")
        self.assertEqual(safeguards.verdict(named, "failed", ["test_step01: hard case: sums"]),
                         "named case passes")
        self.assertEqual(safeguards.verdict(named, "failed", ["test_step01: effects: random",
                                                              "test_step01: hard case: sums"]),
                         "other hard cases fail too")


if __name__ == "__main__":
    unittest.main()
