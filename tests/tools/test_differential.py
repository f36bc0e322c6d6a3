"""Tests of the differential tests' data (tests/differential, tools/grading/differential.py):
a starter kit ships the reference's answers byte for byte with the tests that read them,
so the kit's differential tests compare with the same answers as the tree's. That the
answers are this tree's reference's is the ctest test "differential: the shipped answers
are the reference's" (it regenerates them); that a kit's tests are as strong is the grading
scenarios' (they grade a kit and the reference with the tree's tests)."""
import glob
import os
import re
import shutil
import tempfile
import unittest

from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools import ROOT
from tools.grading import kit

DATA = os.path.join(ROOT, "tests", "differential", "data")


def shipped():
    """The files a kit must carry unchanged: the data, the harness and specs, the tests."""
    files = glob.glob(os.path.join(ROOT, "tests", "differential", "**", "*"), recursive=True)
    files += glob.glob(os.path.join(ROOT, "tests", "step*_differential.cpp"))
    files += glob.glob(os.path.join(ROOT, "tests", "step*_mistakes.cpp"))
    return sorted(os.path.relpath(f, ROOT) for f in files if os.path.isfile(f))


class Data(unittest.TestCase):
    def test_every_data_set_has_its_header_and_one_line_per_input(self):
        sets = glob.glob(os.path.join(DATA, "*.txt"))
        self.assertGreaterEqual(len(sets), 44)
        for path in sets:
            with open(path, encoding="utf-8") as f:
                lines = f.read().split("\n")
            m = re.fullmatch(r"#! (\S+) 1 (\d+)", lines[0])
            self.assertIsNotNone(m, path)
            self.assertEqual(m.group(1) + ".txt", os.path.basename(path))
            records = [l for l in lines[1:] if l and not l.startswith("#")]
            self.assertEqual(len(records), int(m.group(2)), path)

    def test_every_exercise_has_a_data_set(self):
        from tools.grading.exercises import exercises  # noqa: PLC0415

        names = {os.path.basename(p)[:-4].split("-")[0] for p in glob.glob(os.path.join(DATA, "*.txt"))}
        for e in exercises(ROOT):
            self.assertIn(e.id, names, f"exercise {e.id} has no differential data")

    def test_the_data_stays_compact(self):
        # The repository carries it: about 1 MB of text (a third of that compressed).
        total = sum(os.path.getsize(p) for p in glob.glob(os.path.join(DATA, "*.txt")))
        self.assertLess(total, 1_400_000)


class Kit(unittest.TestCase):
    def test_a_kit_ships_the_reference_answers_and_their_tests_unchanged(self):
        dest = tempfile.mkdtemp(prefix="boxes-kit-")
        try:
            shutil.rmtree(dest)
            kit.write_kit(dest)
            files = shipped()
            self.assertTrue(any(f.endswith(".txt") for f in files))
            for rel in files:
                with self.subTest(rel):
                    with open(os.path.join(ROOT, rel), "rb") as a:
                        mine = a.read()
                    self.assertTrue(os.path.isfile(os.path.join(dest, rel)), f"{rel} is not in the kit")
                    with open(os.path.join(dest, rel), "rb") as b:
                        self.assertEqual(b.read(), mine, f"{rel} differs in the kit")
            # The command that writes the answers needs the solutions: not in the kit.
            self.assertFalse(os.path.exists(os.path.join(dest, "tools", "grading", "differential.py")))
            self.assertFalse(os.path.exists(os.path.join(dest, "tools", "grading", "mutant_generator.py")))
        finally:
            shutil.rmtree(dest, ignore_errors=True)


if __name__ == "__main__":
    unittest.main()
