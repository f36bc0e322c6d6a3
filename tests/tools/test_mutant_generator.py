"""Tests of tools/grading/mutant_generator.py (./workbook mutants --generate): which mutants a
line makes (operators with spaces around them, not template brackets or comments), that a
body's keys are stable, and that the schema (every mutant as a case of one switch) is C++
that compiles, with a broken mutant found by the compiler's line numbers. The slow run over
the exercises is ./workbook mutants --generate itself."""
import os
import shutil
import subprocess
import tempfile
import unittest
import unittest.mock

from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools.grading import mutant_generator as gen
from tools.grading.exercises import parse_file

SOURCE = """#include <algorithm>
#include <array>

// EXERCISE 1.1: a clamp and a count (1 point)
int clampCount(std::array<int, 4> values, int lo) {
    int count = 0;
    // BEGIN SOLUTION
    // a comment with a < b and "a string with < inside"
    for (int i = 0; i < 4; ++i) {
        if (values[size_t(i)] < lo) continue;
        count += std::min(values[size_t(i)], 2 * lo);
    }
    if (count == 0) return -1;
    return count;
    // END SOLUTION
}
"""


def write_tree():
    root = tempfile.mkdtemp(prefix="boxes-gen-")
    os.makedirs(os.path.join(root, "steps", "01_x"))
    path = os.path.join(root, "steps", "01_x", "x.cpp")
    with open(path, "w") as f:
        f.write(SOURCE)
    return root, path


class Lines(unittest.TestCase):
    def test_comments_and_literals_are_not_code(self):
        code, still_open = gen.code_mask('a < b; // c < d "e"')
        self.assertEqual(code.strip(), "a < b;")
        self.assertFalse(still_open)
        code, still_open = gen.code_mask('x = "a < b"; /* open')
        self.assertNotIn("<", code)
        self.assertTrue(still_open)

    def test_operators_with_spaces_are_mutated_and_template_brackets_are_not(self):
        line = "    std::vector<int> v; if (a < b && c >= d) x += std::max(y, 2.5f);"
        found = {(rep, op) for _, _, rep, op, _ in gen.line_mutations(line, gen.code_mask(line)[0])}
        self.assertIn(("<=", "boundary"), found)
        self.assertIn((">=", "comparison"), found)  # a < b negated
        self.assertIn((">", "boundary"), found)  # c >= d
        self.assertIn(("||", "logical"), found)
        self.assertIn(("-=", "arithmetic"), found)
        self.assertIn(("std::min", "min/max"), found)
        self.assertIn(("0.0f", "constant"), found)
        self.assertIn(("5.0f", "constant"), found)
        cols = [c for c, _, _, _, _ in gen.line_mutations(line, gen.code_mask(line)[0])]
        self.assertNotIn(line.index("<int>"), cols)

    def test_precision_mutants_of_double_and_of_the_template_type(self):
        line = "    T u = T(double(a) * double(b));"
        found = [d for _, _, _, op, d in gen.line_mutations(line, line) if op == "precision"]
        self.assertEqual(len(found), 3)  # two doubles and the T variable


class Generate(unittest.TestCase):
    def setUp(self):
        self.root, self.path = write_tree()
        (self.ex,) = parse_file(self.path, self.root)

    def tearDown(self):
        shutil.rmtree(self.root, ignore_errors=True)

    def test_mutants_of_the_body_only_with_stable_keys(self):
        mutants = gen.generate(self.path, self.ex)
        self.assertTrue(mutants)
        lines = SOURCE.split("\n")
        for m in mutants:
            self.assertTrue(self.ex.begin < m.line < self.ex.end)
            self.assertNotIn("comment", lines[m.line])
        self.assertEqual([m.key for m in mutants], [m.key for m in gen.generate(self.path, self.ex)])
        self.assertEqual(len({m.key for m in mutants}), len(mutants))
        drops = [m for m in mutants if m.operator == "statement"]
        # The two guards and the += are dropped; the last return is not (it would fall off
        # the end).
        self.assertEqual(len(drops), 3)
        self.assertTrue(any("if (count == 0) return -1;" in m.description for m in drops))

    def test_the_schema_compiles_and_a_broken_mutant_is_found_by_its_line(self):
        if not shutil.which("g++"):
            self.skipTest("no g++")
        mutants = gen.generate(self.path, self.ex)
        broken = next(m for m in mutants if "count +=" in m.original)
        broken.mutated = ["        count += this does not compile;"]
        text, ranges = gen.schema(SOURCE, self.ex, mutants)
        self.assertIn("switch (boxesGeneratedMutant())", text)
        with open(self.path, "w") as f:
            f.write(text)
        r = subprocess.run(["g++", "-std=c++20", "-fsyntax-only", self.path], capture_output=True, text=True)
        self.assertNotEqual(r.returncode, 0)
        lines = gen.error_lines(r.stderr, "steps/01_x/x.cpp")
        bad = {n for n, (a, b) in ranges.items() if any(a <= l <= b for l in lines)}
        self.assertEqual(bad, {broken.number})
        # Without the broken one it compiles, and each mutant runs as its own case.
        mutants = [m for m in mutants if m is not broken]
        text, _ = gen.schema(SOURCE, self.ex, mutants)
        main = text + "\n#include <cstdio>\nint main() { printf(\"%d\\n\", clampCount({1, 5, 3, 9}, 3)); }\n"
        with open(self.path, "w") as f:
            f.write(main)
        exe = os.path.join(self.root, "x")
        r = subprocess.run(["g++", "-std=c++20", "-O1", "-o", exe, self.path], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        outputs = set()
        for n in [0] + [m.number for m in mutants[:6]]:
            out = subprocess.run([exe], env=dict(os.environ, BOXES_MUTANT=str(n)), capture_output=True,
                                 text=True).stdout.strip()
            outputs.add(out)
            if n == 0:
                self.assertEqual(out, "14")  # min(5, 6) + min(3, 6) + min(9, 6)
        self.assertGreater(len(outputs), 1)


class Score(unittest.TestCase):
    def test_the_score_leaves_out_the_equivalent_and_the_table_says_so(self):
        # 1.1: 18 killed, 2 survived, one of them argued equivalent, 1 stillborn: 18 / 19.
        outcome = {f"1.1-k{i}": ("killed", "") for i in range(18)}
        outcome.update({"1.1-eq": ("survived", ""), "1.1-left": ("survived", ""),
                        "1.1-nb": ("stillborn", "does not compile")})
        results = {"1.1": {"outcome": outcome}, "1.2": {"outcome": {"1.2-a": ("killed", "")}}}
        equivalent = {"1.1-eq": {"exercise": "1.1", "why": "the same on every input"}}
        n, still, killed, eq, left, score = gen.score_row("1.1", results["1.1"], equivalent)
        self.assertEqual((n, still, killed, eq, left), (21, 1, 18, 1, ["1.1-left"]))
        self.assertAlmostEqual(score, 100.0 * 18 / 19)
        with unittest.mock.patch("builtins.print") as shown:
            status = gen.print_summary(results, equivalent, markdown=True)
        lines = [c.args[0] for c in shown.call_args_list]
        self.assertIn("| 1.1 | 21 | 1 | 18 | 1 | 1 | 94.7% |", lines)
        self.assertIn("| 1.2 | 1 | 0 | 1 | 0 | 0 | 100.0% |", lines)
        self.assertIn("| all | 22 | 1 | 19 | 1 | 1 | 95.0% |", lines)
        self.assertEqual(status, 1)  # 1.1 is under 95%
        equivalent["1.1-left"] = {"exercise": "1.1", "why": "argued too"}
        with unittest.mock.patch("builtins.print"):
            self.assertEqual(gen.print_summary(results, equivalent, markdown=True), 0)

    def test_an_exercise_without_mutants_has_no_score(self):
        # 5.7's body is one call: nothing to mutate, which is not a 100% score; and a row
        # whose every survivor is argued equivalent has nothing counted either.
        results = {"5.7": {"outcome": {}},
                   "5.8": {"outcome": {"5.8-eq": ("survived", "")}}}
        equivalent = {"5.8-eq": {"exercise": "5.8", "why": "the same on every input"}}
        self.assertIsNone(gen.score_row("5.7", results["5.7"], equivalent)[5])
        with unittest.mock.patch("builtins.print") as shown:
            status = gen.print_summary(results, equivalent, markdown=True)
        lines = [c.args[0] for c in shown.call_args_list]
        self.assertIn("| 5.7 | 0 | 0 | 0 | 0 | 0 | no mutants |", lines)
        self.assertIn("| 5.8 | 1 | 0 | 0 | 1 | 0 | none counted |", lines)
        # The "all" row follows the same rule: nothing counted over both rows, so no 0.0%.
        self.assertIn("| all | 1 | 0 | 0 | 1 | 0 | none counted |", lines)
        self.assertEqual(status, 0)
        with unittest.mock.patch("builtins.print") as shown:
            gen.print_summary(results, equivalent)
        self.assertTrue(any("no mutants" in c.args[0] for c in shown.call_args_list))


if __name__ == "__main__":
    unittest.main()
