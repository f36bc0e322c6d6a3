"""Unit tests of tools/bench/bench04.py and meshes.py: the motorbike's conversion, the meshes
that cannot be had, the rounds' ratios and the agreement of hits."""
import os
import struct
import sys
import tempfile
import unittest
import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from tools.bench import bench04, meshes  # noqa: E402


class Meshes(unittest.TestCase):
    def test_the_motorbike_conversion_drops_repeated_triangles_and_keeps_the_order(self):
        lines = ["# comment", "g one", "v 0 0 0", "v 1.5e-08 0 0", "v 0 1 0", "v 0 0 1",
                 "f 1 2 3", "f 2/7/1 4/7/1 3/7/1", "g two", "f 3 1 2", "f 1 2 3 4", "f -1 -2 -3"]
        text, counts = meshes.convert_motorbike(lines)
        # f 3 1 2 repeats 1 2 3 (any order); the quad's fans are 1 2 3 (a repeat) and 1 3 4;
        # -1 -2 -3 is 4 3 2, a repeat of 2 4 3.
        self.assertEqual(text, "v 0 0 0\nv 1.5e-08 0 0\nv 0 1 0\nv 0 0 1\n"
                               "f 1 2 3\nf 2 4 3\nf 1 3 4\n")
        self.assertEqual(counts, {"vertices": 4, "triangles": 3, "dropped": 3})

    def test_a_mesh_that_cannot_be_had_says_why(self):
        with self.assertRaises(meshes.Unavailable) as e:
            meshes.mesh_path("dragon", tempfile.mkdtemp())
        self.assertEqual(str(e.exception), "dragon: no such mesh (bunny, sh1, motorbike, oa_thor)")
        folder = tempfile.mkdtemp()
        with self.assertRaises(meshes.Unavailable) as e:
            meshes.mesh_path("bunny", tempfile.mkdtemp(), folder)
        self.assertEqual(str(e.exception), "bunny: no %s" % os.path.join(folder, "bunny.obj"))
        self.assertTrue(os.path.exists(meshes.mesh_path("bunny", folder)))


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
