"""Unit tests of tools/bench/bench06.py: the verdict line from a row's ratios."""
import unittest
from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools.bench import bench06


def row(vis, shaded, cpu_vis=None, cpu_shaded=None, no_culling=0.5):
    return {"mesh": "m", "visibility_ratio": vis, "shaded_ratio": shaded,
            "cpu_visibility_ratio": vis if cpu_vis is None else cpu_vis,
            "cpu_shaded_ratio": shaded if cpu_shaded is None else cpu_shaded,
            "no_culling_ratio": no_culling, "step06_no_culling_ms": 20.0, "fragments": 200000,
            "triangles_after_culling": 10, "triangles": 40}


class Verdict(unittest.TestCase):
    def test_met_only_when_wall_and_cpu_ratios_reach_one(self):
        self.assertIn("target met", bench06.verdict(row(1.0, 1.3), 100000))
        v = bench06.verdict(row(1.1, 1.3, cpu_vis=0.8), 100000)
        self.assertIn("target missed", v)
        # 1 / 1.1 and 1 / 0.8, the shaded pass not named
        self.assertIn("visibility takes 0.91x llvmpipe's time (CPU time 1.25x)", v)
        self.assertNotIn("shaded takes", v)

    def test_missed_names_the_work_per_pixel_centre(self):
        v = bench06.verdict(row(0.25, 0.5, no_culling=0.2), 100000)
        self.assertIn("visibility takes 4.00x", v)
        self.assertIn("shaded takes 2.00x", v)
        # 200,000 centres over 100,000 pixels; 20 ms / 200,000 = 100 ns
        self.assertIn("200000 of them, 2.0 per pixel; 100 ns each", v)
        self.assertNotIn("culling costs more", v)
        self.assertIn("culling costs more than it saves here (without it, visibility at x0.90)",
                      bench06.verdict(row(0.8, 1.2, no_culling=0.9), 100000))


if __name__ == "__main__":
    unittest.main()
