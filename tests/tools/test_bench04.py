"""Unit tests of tools/bench/bench04.py: the folders it needs from outside the workbook, the
rounds' ratios and the agreement of hits."""
import os
import struct
import sys
import tempfile
import unittest
from unittest import mock
import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from tools.bench import bench04  # noqa: E402


class OutsidePaths(unittest.TestCase):
    def test_flags_first_then_the_variables(self):
        a, b = tempfile.mkdtemp(), tempfile.mkdtemp()
        with mock.patch.dict(os.environ, {"BOXES_MESHES": b, "BOXES_PEER_BENCH": b}):
            self.assertEqual(bench04.outside_paths(a, None), (a, b))
            self.assertEqual(bench04.outside_paths(None, a), (b, a))

    def test_a_missing_one_is_named_with_its_flag_and_variable(self):
        with mock.patch.dict(os.environ, {}, clear=True):
            with self.assertRaises(SystemExit) as e:
                bench04.outside_paths(None, tempfile.mkdtemp())
            self.assertEqual(str(e.exception), "bench04: the meshes folder (MESH.obj for every --meshes name) "
                                               "is not given: pass --data DIR or set BOXES_MESHES")
            with self.assertRaises(SystemExit) as e:
                bench04.outside_paths(tempfile.mkdtemp(), None)
            self.assertIn("pass --peer-dir DIR or set BOXES_PEER_BENCH", str(e.exception))
            with self.assertRaises(SystemExit) as e:
                bench04.outside_paths("/nonexistent/meshes", tempfile.mkdtemp())
            self.assertEqual(str(e.exception), "bench04: --data / BOXES_MESHES /nonexistent/meshes: no such folder")


class Ratios(unittest.TestCase):
    def test_per_round_ratios_sorted(self):
        ours = [{"s": 2.0}, {"s": 3.0}, {"s": 1.0}]
        theirs = [{"s": 4.0}, {"s": 3.0}, {"s": 4.0}]
        self.assertEqual(bench04.round_ratios(ours, theirs, "s"), [0.25, 0.5, 1.0])

    def test_hits_agree_by_triangle_or_distance(self):
        path = os.path.join(tempfile.mkdtemp(), "hits.bin")
        with open(path, "wb") as f:
            f.write(struct.pack("<fIfI", 1.5, 7, 2.0, 9))
        hits = bench04.read_hits(path)
        self.assertEqual(hits, [(1.5, 7), (2.0, 9)])
        self.assertEqual(bench04.agreement(hits, [(1.5, 8), (3.0, 9)]), 1.0)
        self.assertEqual(bench04.agreement(hits, [(1.0, 8), (3.0, 9)]), 0.5)
        self.assertEqual(bench04.agreement([], []), 0.0)


if __name__ == "__main__":
    unittest.main()
