"""Unit tests of tools/report.py and tools/plots.py: the Pareto front of error against time, its plot, the page."""
import json
import os
import re
import tempfile
import unittest
from unittest import mock

from tests.tools import scratch  # noqa: F401  (tempfile's folders go into one removed at exit)

from tools import png, report
from tools.plots import pareto_front, plot
from tools.report import table_html


class ParetoFront(unittest.TestCase):
    def test_dominated_points_are_left_out(self):
        # (time, error): (2, 5) is beaten by (1, 4) on both; (3, 4) ties on error but is slower.
        points = [(1, 4), (2, 5), (3, 4), (4, 0), (2, 1)]
        self.assertEqual(pareto_front(points), [(1, 4), (2, 1), (4, 0)])

    def test_one_point_and_equal_points(self):
        self.assertEqual(pareto_front([(3, 3)]), [(3, 3)])
        self.assertEqual(pareto_front([(1, 0), (1, 0)]), [(1, 0)])

    def test_zero_errors_leave_the_fastest(self):
        # Every variant exact: only time decides (step 04's builders).
        self.assertEqual(pareto_front([(5, 0), (2, 0), (9, 0)]), [(2, 0)])

    def test_the_faster_of_two_equal_times_wins_on_error(self):
        self.assertEqual(pareto_front([(2, 7), (2, 3)]), [(2, 3)])


class Report(unittest.TestCase):
    TABLE = {"id": "t", "title": "T", "note": "against a reference", "columns": ["v", "ms", "lo", "hi", "err"],
             "time": {"median": "ms", "low": "lo", "high": "hi"}, "error": "err",
             "rows": [["a", 1.0, 0.9, 1.1, 3.0], ["b", 2.0, 1.9, 2.1, 4.0], ["c", 3.0, 2.9, 3.1, 0.0]]}

    def test_plot_with_the_front_writes_a_png(self):
        report = {"tables": [self.TABLE]}
        spec = {"table": "t", "x": "ms", "y": "err", "series": "v", "pareto": True}
        with tempfile.TemporaryDirectory() as out:
            name = plot(report, spec, out, "p.png")
            self.assertEqual(name, "p.png")
            with open(os.path.join(out, name), "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")

    def test_table_names_its_time_and_error(self):
        text = table_html(json.loads(json.dumps(self.TABLE)))
        self.assertIn("Time: <i>ms</i> (spread <i>lo</i> to <i>hi</i>); error: <i>err</i>", text)


class StepGuide(unittest.TestCase):
    """A step's section as a guide: the README's summary and marked points from the claims
    check (out/claims.json), the links, the takeaways, the facts in words with units."""

    def test_the_section_says_what_to_conclude(self):
        step = {"program": "01_triangle", "machine": "m", "images": [], "plots": [],
                "facts": {"render_ms": 12.5, "pixels_disagreeing": 3, "made_up_count": 1200,
                          "refined_image_bit_identical": True},
                "tables": [dict(Report.TABLE, rows=[["a", 1.0, 0.9, 1.1, 3.0]] * 7)]}
        claims = {"counts": {"agree": 2, "fail": 0, "notMeasured": 0}, "guides": {"01_triangle": {
            "summary": "It measured **this**. Conclude that.",
            "bullets": [{"text": "A point, see [measuring.md](../../docs/measuring.md#x)", "status": "agree",
                         "checks": [{"expression": "1 == 1", "status": "agree", "shown": "1 == 1"}]},
                        {"text": "Another", "status": "unchecked", "checks": []}],
            "takeaways": {"t": "Take `this` away."}}}}
        with tempfile.TemporaryDirectory() as out:
            for name, data in (("01_triangle.json", step), ("claims.json", claims)):
                with open(os.path.join(out, name), "w") as f:
                    json.dump(data, f)
            with mock.patch("sys.argv", ["report", out]), mock.patch("sys.stderr"):
                report.main()
            with open(os.path.join(out, "index.html"), encoding="utf-8") as f:
                text = f.read()
        self.assertIn("<p class=summary>It measured <b>this</b>. Conclude that.</p>", text)
        self.assertIn("class='point agree'", text)
        self.assertIn("agrees with this run", text)
        self.assertIn("class='point unchecked'", text)
        root = os.path.relpath(report.ROOT, out)
        self.assertIn(f"<a href='{os.path.join(root, 'docs', 'measuring.md')}#x'>measuring.md</a>", text)
        self.assertIn(f"class=readme href='{os.path.join(root, 'steps', '01_triangle', 'README.md')}'", text)
        self.assertIn("class=measuring href=", text)
        self.assertIn("<details><summary>T", text)  # 7 rows: folded
        self.assertIn("<span class=label>Takeaway</span> Take <code>this</code> away.", text)
        self.assertIn("<dt>The image&#x27;s render time</dt><dd>12.5 ms</dd>", text)
        self.assertIn("<dt>Made up count</dt><dd>1,200</dd>", text)
        self.assertIn("<dd>yes</dd>", text)
        self.assertNotIn("made_up_count", text)


class ExerciseStatus(unittest.TestCase):
    """The page's exercise table: the tour's test results, check's status where the tour ran
    no test of the exercise, and a link to check's picture."""

    def page(self, tour_cases, status):
        with tempfile.TemporaryDirectory() as out:
            os.makedirs(os.path.join(out, "check"))
            if tour_cases is not None:
                with open(os.path.join(out, "test_step01.xml"), "w") as f:
                    f.write(f'<doctest><TestSuite name="exercise 1.4">{tour_cases}</TestSuite></doctest>')
            with open(os.path.join(out, "check", "status.json"), "w") as f:
                json.dump({"time": "12:00", "exercises": status}, f)
            png.write(os.path.join(out, "check", "1.4.png"), 1, 1, [bytearray(3)])
            with mock.patch("sys.argv", ["report", out]), mock.patch("sys.stderr"):
                report.main()
            with open(os.path.join(out, "index.html"), encoding="utf-8") as f:
                text = f.read()
        return {m[1]: m for m in re.findall(r"<tr class=(\w+)><td>([\d.]+)</td>(.*?)</tr>", text)}, text

    CHECKED = [{"id": "1.4", "status": "failed", "picture": "out/check/1.4.png: 12 of 19200 pixels differ"},
               {"id": "1.5", "status": "not started", "picture": "the bunny: once the exercise runs"}]

    def test_the_tours_results_and_checks_picture(self):
        passing = ('<TestCase name="c"><OverallResultsAsserts successes="1" failures="0" '
                   'test_case_success="true"/></TestCase>')
        rows, _ = self.page(passing, self.CHECKED)
        css, _, cells = rows["1.4"]
        self.assertEqual(css, "passed")
        self.assertIn("<td>1/1</td><td>passed</td>", cells)
        self.assertIn("<a href='check/1.4.png' title='out/check/1.4.png: 12 of 19200 pixels differ'>picture</a>",
                      cells)
        self.assertIn("(failed at 12:00)", cells)  # check's picture is of its own, older run

    def test_checks_status_where_the_tour_ran_no_test(self):
        rows, text = self.page(None, self.CHECKED)
        self.assertEqual(rows["1.4"][0], "failed")
        self.assertIn("<td>-</td><td>failed</td>", rows["1.4"][2])
        self.assertEqual(rows["1.5"][0], "notstarted")
        self.assertIn("once the exercise runs", rows["1.5"][2])
        self.assertIn("<td>not run</td>", rows["1.6"][2])  # neither ran it


if __name__ == "__main__":
    unittest.main()
