"""Unit tests of tools/bench/bench04.py and meshes.py: the motorbike's conversion, the meshes
that cannot be had, the rounds' ratios and the agreement of hits."""
import os
import struct
import tempfile
import unittest
from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools.bench import bench04, meshes, q3map


def tiny_map():
    """A Quake III map (IBSP 46) by hand: a quad as two triangles plus a repeat and a
    zero-area triangle, a sky face, and a flat 3x3 Bezier patch at z = 5."""
    textures = struct.pack("<64sii", b"wall", 0, 0) + struct.pack("<64sii", b"sky", 4, 0)
    quad = [(0, 0, 0), (4, 0, 0), (4, 4, 0), (0, 4, 0)]
    patch = [(i, j, 5) for j in range(3) for i in range(3)]
    vertices = b"".join(struct.pack("<3f32x", *p) for p in quad + patch)
    meshverts = struct.pack("<12i", 0, 1, 2, 0, 2, 3, 2, 1, 0, 0, 1, 1)

    def face(texture, kind, vertex, count, meshvert, nmeshverts, size=(0, 0)):
        return struct.pack("<7i", texture, 0, kind, vertex, count, meshvert, nmeshverts) + \
            bytes(96 - 28) + struct.pack("<2i", *size)
    faces = face(0, 1, 0, 4, 0, 12) + face(1, 1, 0, 4, 0, 6) + face(0, 2, 4, 9, 0, 0, (3, 3))
    models = struct.pack("<6f4i", 0, 0, 0, 4, 4, 5, 0, 3, 0, 0)
    body = {1: textures, 7: models, 10: vertices, 11: meshverts, 13: faces}
    offset, directory, blob = 8 + 17 * 8, b"", b""
    for i in range(17):
        data = body.get(i, b"")
        directory += struct.pack("<ii", offset + len(blob), len(data))
        blob += data
    return b"IBSP" + struct.pack("<i", 46) + directory + blob


class QuakeMap(unittest.TestCase):
    def test_faces_patches_and_what_is_left_out(self):
        positions, tris, counts = q3map.triangles(tiny_map())
        self.assertEqual(counts, {"sky": 1, "zero_area": 1, "repeats": 1})
        # 2 triangles of the quad, 4 x 4 quads of two triangles from the patch
        self.assertEqual(len(tris), 2 + 32)
        self.assertEqual([positions[i] for i in tris[0]], [(0, 0, 0), (4, 0, 0), (4, 4, 0)])
        self.assertEqual(len(positions), 4 + 25)
        # the flat patch's control grid is x = i, y = j: its points are the grid's, e.g. the
        # middle (1, 1, 5) and a quarter step (0.5, 0.5, 5)
        self.assertIn((1.0, 1.0, 5.0), positions)
        self.assertIn((0.5, 0.5, 5.0), positions)

    def test_another_file_is_refused(self):
        with self.assertRaises(ValueError):
            q3map.triangles(b"PK\x03\x04" + bytes(200))


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


class Targets(unittest.TestCase):
    def test_each_target_met_or_missed_by_its_worst_mesh(self):
        rows = [{"builder": b, "mesh": m, "kind": k, "ratio": r} for b, m, k, r in [
            ("sah 8-wide", "bunny", "primary", 1.2), ("sbvh 8-wide", "bunny", "primary", 1.4),
            ("sah 8-wide", "thor", "primary", 1.35), ("sbvh 8-wide", "bunny", "diffuse", 0.8),
            ("sah", "bunny", "primary", 0.75), ("sah", "thor", "primary", 0.6)]]
        threads = [{"mesh": "bunny", "kind": "primary", "speedup": 1.95}]
        lines = bench04.target_lines(rows, threads)
        self.assertEqual(len(lines), 4)
        # The best of the two 8-wide trees per mesh: 1.4 and 1.35, both >= 1.3.
        self.assertIn("met (bunny 1.40x, thor 1.35x)", lines[0])
        # Diffuse: 0.8 against 1.0 is 20% short.
        self.assertIn("missed by 20% (bunny 0.80x)", lines[1])
        # The binary tree: its worst mesh decides (0.6 against 0.75: 20% short).
        self.assertIn("missed by 20% (bunny 0.75x, thor 0.60x)", lines[2])
        self.assertIn(">= 1.90x: met (bunny primary 1.95x)", lines[3])


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
