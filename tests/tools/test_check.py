"""Unit tests of the student's check (tools/check.py), its pictures (tools/pictures.py) and
the PNG reader (tools/png.py): no build, no test program."""
import os
import re
import stat
import tempfile
import time
import unittest
from unittest import mock

from tests.tools import scratch  # noqa: F401  (tempfile's folders go into one removed at exit)

from tools import ROOT
from tools import check, label, pictures, png
from tools.grading.exercises import exercises


def xml(*cases):
    body = "".join(cases)
    return f'<doctest><TestSuite name="exercise 1.4">{body}</TestSuite></doctest>'.encode()


def case(name, failures=0, inner=""):
    return (f'<TestCase name="{name}" filename="/x/tests/step01_triangle.cpp" line="12">{inner}'
            f'<OverallResultsAsserts successes="1" failures="{failures}" '
            f'test_case_success="{"false" if failures else "true"}"/></TestCase>')


def stub_exception(ex):
    return f'<Exception crash="false">exercise {ex} is not implemented yet</Exception>'


FAILED_CHECK = ('<Expression success="false" type="CHECK" filename="/x/tests/step01_triangle.cpp" '
                'line="40"><Original>!hit.has_value()</Original><Expanded>false</Expanded>'
                '<Info>ray O (0, 0, -1) D (0.9, 0.9, 1)</Info></Expression>')


class Classify(unittest.TestCase):
    def test_all_passing_is_passed(self):
        self.assertEqual(check.classify("1.4", check.parse_cases(xml(case("a"), case("b"))))[0], "passed")

    def test_own_stub_is_not_started_not_a_failure(self):
        cases = check.parse_cases(xml(case("a", 1, stub_exception("1.4")), case("b", 1, stub_exception("1.4"))))
        self.assertEqual(check.classify("1.4", cases)[0], "not started")

    def test_an_earlier_stub_names_the_exercise_needed(self):
        cases = check.parse_cases(xml(case("a", 1, stub_exception("1.1")), case("b")))
        self.assertEqual(check.classify("1.4", cases)[0], "needs 1.1")

    def test_a_wrong_answer_is_failed_with_its_check(self):
        cases = check.parse_cases(xml(case("a"), case("past the second edge", 1, FAILED_CHECK)))
        status, first = check.classify("1.4", cases)
        self.assertEqual(status, "failed")
        self.assertEqual(first["name"], "past the second edge")
        self.assertEqual(first["failure"]["expression"], "!hit.has_value()")
        self.assertEqual(first["failure"]["infos"], ["ray O (0, 0, -1) D (0.9, 0.9, 1)"])

    def test_a_failing_case_of_a_catalogued_mistake_is_shown_first(self):
        cases = check.parse_cases(xml(case("worked hits", 1, FAILED_CHECK),
                                      case("past the third edge", 1, FAILED_CHECK)))
        mistakes = {"past the third edge": {"exercise": "1.4", "hint": "check u + v"},
                    "worked hits": {"exercise": "1.3", "hint": "another exercise's"}}
        self.assertEqual(check.classify("1.4", cases)[1]["name"], "worked hits")
        status, shown = check.classify("1.4", cases, mistakes)
        self.assertEqual((status, shown["name"]), ("failed", "past the third edge"))
        self.assertEqual(check.hint_for({"id": "1.4", "case": shown}, ({}, mistakes)),
                         ("check u + v", True))

    def test_the_case_whose_mistake_fails_like_this_one_is_shown(self):
        # A strict comparison fails the worked examples and the touching boxes; the worked
        # examples are the catalogued case of another mistake (one axis only), which fails
        # them alone: the touching boxes' case names this mistake.
        cases = check.parse_cases(xml(case("worked examples", 1, FAILED_CHECK),
                                      case("touching boxes", 1, FAILED_CHECK), case("other")))
        check_ = "!hit.has_value()"
        info = "ray O (0, 0, -1) D (0.9, 0.9, 1)"
        fails = lambda *names: {k: 1 for n in names for k in (f"{n} | {check_}", f"{n} | {check_} | {info}")}
        mistakes = {"worked examples": {"exercise": "1.4", "hint": "all axes",
                                        "fails": fails("worked examples")},
                    "touching boxes": {"exercise": "1.4", "hint": "compare with <=",
                                       "fails": fails("worked examples", "touching boxes")}}
        status, shown = check.classify("1.4", cases, mistakes)
        self.assertEqual(shown["name"], "touching boxes")
        self.assertEqual(check.hint_for({"id": "1.4", "status": status, "case": shown}, ({}, mistakes)),
                         ("compare with <=", True))
        # The worked examples alone failing: that mistake's own case and hint.
        alone = check.parse_cases(xml(case("worked examples", 1, FAILED_CHECK), case("touching boxes")))
        self.assertEqual(check.classify("1.4", alone, mistakes)[1]["name"], "worked examples")

    def test_a_not_started_exercise_gets_its_exercise_hint(self):
        cases = check.parse_cases(xml(case("touching boxes", 1, stub_exception("1.4"))))
        mistakes = {"touching boxes": {"exercise": "1.4", "hint": "compare with <="}}
        status, shown = check.classify("1.4", cases, mistakes)
        self.assertEqual(status, "not started")
        self.assertEqual(check.hint_for({"id": "1.4", "status": status, "case": shown},
                                        ({"1.4": "generic"}, mistakes)), ("generic", False))

    def test_no_cases_is_no_tests(self):
        self.assertEqual(check.classify("1.4", [])[0], "no tests")

    def test_unreadable_results_are_none(self):
        self.assertIsNone(check.parse_cases(b"<doctest><TestSuite"))


class Words(unittest.TestCase):
    def test_plain_words_name_the_case_the_check_the_values_and_the_input(self):
        cases = check.parse_cases(xml(case("past the second edge", 1, FAILED_CHECK)))
        row = {"id": "1.4", "status": "failed", "case": check.classify("1.4", cases)[1]}
        text = "\n".join(check.describe_failure(row, "/x"))
        self.assertIn('"past the second edge"', text)
        self.assertIn("CHECK( !hit.has_value() ) failed at tests/step01_triangle.cpp:40", text)
        self.assertIn("with the values: false", text)
        self.assertIn("input: ray O (0, 0, -1)", text)

    def test_compile_errors_relative_to_the_tree(self):
        out = "FAILED: x.o\n../../steps/01_triangle/triangle.cpp:60:5: error: 'foo' was not declared\n"
        self.assertEqual(check.first_compile_error(out, "/r"),
                         "steps/01_triangle/triangle.cpp:60: 'foo' was not declared")


class Selection(unittest.TestCase):
    def setUp(self):
        self.all = exercises(ROOT)

    def test_one_exercise_one_step_and_everything(self):
        self.assertEqual([e.id for e in check.select(self.all, ["1.4"])], ["1.4"])
        self.assertEqual([e.id for e in check.select(self.all, ["01"])], [e.id for e in self.all if e.step == 1])
        self.assertEqual(len(check.select(self.all, [])), len(self.all))

    def test_in_order_whatever_the_order_asked(self):
        self.assertEqual([e.id for e in check.select(self.all, ["1.5", "1.2"])], ["1.2", "1.5"])

    def test_unknown_names_are_refused(self):
        for bad in ("9.9", "1.44", "99", "x"):
            with self.assertRaises(ValueError):
                check.select(self.all, [bad])


# A stand-in for a step's test program: it writes doctest's XML for the suite asked, after
# running BODY (shell) for exercise 1.1; every other exercise passes.
FAKE = """#!/bin/sh
for a; do case $a in --out=*) out=${a#--out=} ;; --test-suite=*) suite=${a#--test-suite=} ;; esac; done
printf '<doctest><TestSuite name="%s"><TestCase name="its case" filename="t.cpp" line="1">' "$suite" >"$out"
[ "$suite" = "exercise 1.1" ] && { BODY ; }
printf '<OverallResultsAsserts successes="1" failures="0" test_case_success="true"/></TestCase></TestSuite></doctest>' >>"$out"
"""


class Limits(unittest.TestCase):
    """An exercise whose tests crash or hang is reported as such, and check goes on."""

    def tree(self, tmp, body):
        tests = os.path.join(tmp, check.BUILD, "tests")
        os.makedirs(tests)
        path = os.path.join(tests, "test_step01")
        with open(path, "w") as f:
            f.write(FAKE.replace("BODY", body))
        os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR)
        return path

    def run_check(self, body, timeout=60.0):
        chosen = [e for e in exercises(ROOT) if e.id in ("1.1", "1.2")]
        opts = mock.Mock(timeout=timeout, jobs=None)
        with tempfile.TemporaryDirectory() as tmp:
            self.tree(tmp, body)
            with mock.patch.object(check, "configure", return_value=None), \
                 mock.patch.object(check, "build_step", return_value=None):
                return {r["id"]: r for r in check.check_once(tmp, chosen, opts)}

    def test_a_crash_names_its_signal_and_case_and_the_next_exercise_runs(self):
        rows = self.run_check("kill -SEGV $$")
        self.assertEqual(rows["1.1"]["status"], "crashed")
        self.assertEqual(rows["1.1"]["detail"], 'SIGSEGV in test case "its case"')
        self.assertEqual(rows["1.2"]["status"], "passed")

    def test_a_hang_is_stopped_at_the_time_limit_and_the_next_exercise_runs(self):
        started = time.monotonic()
        rows = self.run_check("sleep 300", timeout=1.0)
        self.assertLess(time.monotonic() - started, 100)  # stopped, not waited for
        self.assertEqual(rows["1.1"]["status"], "timed out")
        self.assertEqual(rows["1.1"]["detail"], '1 s in test case "its case"')
        self.assertEqual(rows["1.2"]["status"], "passed")

    def test_in_order_the_steps_after_the_next_exercise_are_neither_built_nor_run(self):
        chosen = [e for e in exercises(ROOT) if e.id in ("1.1", "1.2", "2.1")]
        opts = mock.Mock(timeout=60.0, jobs=None)
        with tempfile.TemporaryDirectory() as tmp:
            self.tree(tmp, "exit 7")
            with mock.patch.object(check, "configure", return_value=None), \
                 mock.patch.object(check, "build_step", return_value=None) as built:
                rows = {r["id"]: r for r in check.check_once(tmp, chosen, opts, in_order=True)}
        self.assertEqual(rows["1.2"]["status"], "passed")  # the rest of the next one's step
        self.assertEqual(rows["2.1"]["status"], "not checked")
        self.assertEqual([c.args[1] for c in built.call_args_list], [1])

    def test_an_odd_exit_code_is_a_crash(self):
        rows = self.run_check("exit 7")
        self.assertEqual(rows["1.1"]["status"], "crashed")
        self.assertTrue(rows["1.1"]["detail"].startswith("exit code 7"), rows["1.1"]["detail"])


class NoStalePicture(unittest.TestCase):
    def test_a_timed_out_exercise_renders_nothing_and_its_old_picture_goes(self):
        row = {"id": "1.4", "status": "timed out", "step": 1}
        with tempfile.TemporaryDirectory() as tmp:
            old = os.path.join(tmp, check.OUT, "1.4.png")
            os.makedirs(os.path.dirname(old))
            with open(old, "wb") as f:
                f.write(b"an older run's picture")
            with mock.patch.object(check, "build_targets") as built, \
                 mock.patch.object(pictures, "render") as rendered:
                shown = check.make_pictures(tmp, [row], row, mock.Mock(jobs=None))
            built.assert_not_called()
            rendered.assert_not_called()
            self.assertEqual(shown["1.4"], "none: its tests did not finish, so its picture is not rendered")
            self.assertFalse(os.path.exists(old))


class Hints(unittest.TestCase):
    def test_every_exercise_has_a_short_hint(self):
        generic, mistakes = check.load_hints(ROOT)
        self.assertIsInstance(mistakes, dict)
        for e in exercises(ROOT):
            hint = generic.get(e.id, "")
            self.assertTrue(hint, f"exercise {e.id} has no hint in tests/hints/exercises.json")
            sentences = len(re.findall(r"[.!?](\s|$)", hint))
            self.assertIn(sentences, (1, 2), f"exercise {e.id}: one or two sentences")

    def test_a_catalogued_mistake_replaces_the_generic_hint(self):
        hints = ({"1.4": "generic"}, {"past the second edge": {"exercise": "1.4", "hint": "check v"}})
        row = {"id": "1.4", "case": {"name": "past the second edge"}}
        self.assertEqual(check.hint_for(row, hints), ("check v", True))
        row = {"id": "1.4", "case": {"name": "another case"}}
        self.assertEqual(check.hint_for(row, hints), ("generic", False))
        # A mistake of another exercise does not apply.
        row = {"id": "1.5", "case": {"name": "past the second edge"}}
        self.assertEqual(check.hint_for(row, ({"1.5": "g5"}, hints[1])), ("g5", False))


class Pictures(unittest.TestCase):
    def test_every_exercise_has_a_picture_or_says_why_not(self):
        ids = {e.id for e in exercises(ROOT)}
        with_picture = {i for p in pictures.PICTURES for i in p[3]}
        self.assertLessEqual(with_picture, ids)
        self.assertLessEqual(set(pictures.NOT_SHOWN), ids - with_picture)

    def test_png_round_trip_and_the_difference_count(self):
        with tempfile.TemporaryDirectory() as tmp:
            a, b, out = (os.path.join(tmp, n) for n in ("a.png", "b.png", "c.png"))
            rows = [bytearray([10, 20, 30] * 5) for _ in range(4)]
            png.write(a, 5, 4, rows)
            self.assertEqual(png.read(a), (5, 4, rows))
            changed = [bytearray(r) for r in rows]
            changed[1][0:3] = b"\xff\xff\xff"  # one pixel far off
            changed[2][3:6] = bytes([12, 22, 32])  # within the tolerance
            png.write(b, 5, 4, changed)
            self.assertEqual(pictures.compare(b, a, out), 1)
            w, h, composite = png.read(out)
            strip = h - 4  # the panels' names above them
            self.assertEqual(w, 3 * 5 + 8)
            self.assertGreater(strip, label.GLYPH_H)
            x = 2 * 5 + 8  # the differences panel
            self.assertEqual(tuple(composite[strip + 1][3 * x : 3 * x + 3]), pictures.MARK)
            ring = x + pictures.RING_RADIUS  # its ring, in the same row
            self.assertEqual(tuple(composite[strip + 1][3 * ring : 3 * ring + 3]), pictures.MARK)

    def test_the_check_picture_names_its_panels(self):
        # Wide enough panels for the names: each drawn over its own panel, in ink.
        with tempfile.TemporaryDirectory() as tmp:
            a, out = os.path.join(tmp, "a.png"), os.path.join(tmp, "c.png")
            png.write(a, 120, 10, [bytearray([90, 90, 90] * 120) for _ in range(10)])
            self.assertEqual(pictures.compare(a, a, out), 0)
            w, h, composite = png.read(out)
            strip = h - 10
            for k in range(3):  # each panel's part of the strip holds ink
                inked = sum(1 for y in range(strip) for x in range(k * 124, k * 124 + 120)
                            if composite[y][3 * x] < 128)
                self.assertGreater(inked, 20, f"panel {k} has no name")
            words = [bytearray(b"\xff" * 3 * 200) for _ in range(label.GLYPH_H)]
            label.draw(words, 0, 0, "yours", (0, 0, 0))
            self.assertEqual(label.text_width("yours"), 29)
            self.assertTrue(any(b == 0 for row in words for b in row[: 3 * 29]))
            self.assertFalse(any(b == 0 for row in words for b in row[3 * 29 :]))

    def test_not_a_png_is_one_clear_error(self):
        with tempfile.NamedTemporaryFile(suffix=".png") as f:
            f.write(b"hello")
            f.flush()
            with self.assertRaises(png.PngError):
                png.read(f.name)


if __name__ == "__main__":
    unittest.main()
