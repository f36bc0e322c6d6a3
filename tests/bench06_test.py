#!/usr/bin/python3
"""The bench's rasterizer row end to end, small: tools/bench/bench06.py draws the bunny (and
the interior map where Debian's openarena-088-data is installed) with step 06 and with Mesa's
llvmpipe at 80x60 and reports ratios and the agreement.

usage: bench06_test.py RASTER_GL   (exit 77: no llvmpipe through EGL here)
"""
import json
import math
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
THOR = "/usr/share/games/openarena/baseoa/pak6-patch088.pk3"


def main():
    program = sys.argv[1]
    meshes = "bunny,oa_thor" if os.path.exists(THOR) else "bunny"
    with tempfile.TemporaryDirectory(prefix="boxes-bench06-") as work:
        out = os.path.join(work, "bench06.json")
        r = subprocess.run([sys.executable, "-m", "tools.bench.bench06",
                            "--width", "80", "--height", "60", "--repeat", "2", "--rounds", "2",
                            "--meshes", meshes, "--program", program, "--out", out],
                           capture_output=True, text=True, timeout=120, cwd=ROOT)
        if r.returncode != 0 and "SDL" in r.stderr:
            print("SKIP: no OpenGL context here (tools/deps.sh bench): " + r.stderr[-300:])
            return 77
        assert r.returncode == 0, r.stdout + r.stderr
        with open(out) as f:
            report = json.load(f)
    rows = {row["mesh"]: row for row in report["rows"]}
    assert sorted(rows) == sorted(meshes.split(",")), rows.keys()
    for mesh, row in rows.items():
        assert "llvmpipe" in row["renderer"], row["renderer"]
        for key in ("visibility_ratio", "shaded_ratio", "cpu_visibility_ratio",
                    "cpu_shaded_ratio"):
            assert math.isfinite(row[key]) and row[key] > 0, (mesh, key, row[key])
        # each ratio is the median of two rounds' ratios, each one finite and positive
        assert len(row["visibility_rounds"]) == 2, row["visibility_rounds"]
        assert row["agreement"] >= 0.995, (mesh, row["agreement"])
        assert row["fragments"] > 0 and row["triangles"] > 1000, row
    # the printed table: a ratio and an agreement per mesh
    for mesh in rows:
        line = [l for l in r.stdout.splitlines() if l.startswith(mesh + " ")]
        assert line and len(line[0].split()) == 11, r.stdout
    print(r.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
