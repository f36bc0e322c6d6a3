"""Unit tests of tools/report.py: the Pareto front of error against time, and its plot."""
import json
import os
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from tools.report import pareto_front, plot, table_html  # noqa: E402


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


if __name__ == "__main__":
    unittest.main()
