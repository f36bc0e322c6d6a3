#!/usr/bin/python3
"""Step 06's rasterizer beside Mesa's llvmpipe: the same triangles, view and size, one thread.

usage: python3 -m tools.bench.bench06 [--meshes bunny,oa_thor] [--width 640] [--height 480]
                        [--repeat K] [--rounds R] [--out out/06_raster_bench.json]
                        [--program PATH] [--cache DIR] [--data DIR | BOXES_MESHES=DIR]
       (./workbook bench, after step 04's rows; ./workbook bench raster [ARGS...]: only these)

For every mesh, tools/bench/raster_gl draws one view (the bunny's scene camera; the interior
map oa_thor from the camera inside it) with step 06 and with OpenGL on llvmpipe (SDL's
offscreen driver, EGL; LP_NUM_THREADS=1), visibility only (the triangle per pixel and the
depth) and shaded (the direct light of the scene's point lights, no shadows), --rounds
rounds of every variant in turn, each the median of --repeat frames. A ratio is llvmpipe's
time over step 06's (above 1: step 06 is faster), the median of the rounds' own ratios, from
wall time and from the process's CPU time (which counts llvmpipe's rasterizer thread too).
Agreement: the share of covered pixels where both name the same triangle. Also step 06
without its frustum culling, and llvmpipe with the depth buffer only (no triangle output).
Prints the table and writes it as JSON (for the report).
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys

from .. import ROOT
from . import machine, meshes
TARGET = 1.0  # step 06 at least as fast as llvmpipe
AGREEMENT = 0.995


def run_view(a, mesh, obj):
    cmd = [a.program, "--width", str(a.width), "--height", str(a.height), "--repeat",
           str(a.repeat), "--rounds", str(a.rounds)]
    cmd += ["--scene", "bunny"] if mesh == "bunny" and not a.data else ["--scene", obj]
    if mesh == "oa_thor":
        cmd.append("--inside")
    env = dict(os.environ, LP_NUM_THREADS=os.environ.get("LP_NUM_THREADS", "1"),
               LIBGL_ALWAYS_SOFTWARE="1", GALLIUM_DRIVER="llvmpipe")
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env)
    return json.loads(out.stdout.strip().splitlines()[-1])


def ms(r, variant):
    return statistics.median(r["variants"][variant]["ms"])


def row_of(mesh, r):
    """The printed and reported figures of one view (r: raster_gl's JSON line)."""
    s, c = r["speed_vs_llvmpipe"], r["cpu_speed_vs_llvmpipe"]
    agree = min(r["agreement"]["visibility"]["same_triangle_share"],
                r["agreement"]["shaded"]["same_triangle_share"])
    return {"mesh": mesh, "triangles": r["triangles"],
            "triangles_after_culling": r["triangles_after_culling"],
            "fragments": r["fragments"],
            "step06_visibility_ms": ms(r, "step06 visibility"),
            "llvmpipe_visibility_ms": ms(r, "llvmpipe visibility"),
            "step06_shaded_ms": ms(r, "step06 shaded"),
            "llvmpipe_shaded_ms": ms(r, "llvmpipe shaded"),
            "step06_no_culling_ms": ms(r, "step06 visibility, no culling"),
            "llvmpipe_depth_only_ms": ms(r, "llvmpipe depth only"),
            "visibility_ratio": s["visibility"]["median"],
            "visibility_rounds": s["visibility"]["rounds"],
            "shaded_ratio": s["shaded"]["median"], "shaded_rounds": s["shaded"]["rounds"],
            "no_culling_ratio": s["visibility_no_culling"]["median"],
            "depth_only_ratio": s["visibility_vs_depth_only"]["median"],
            "cpu_visibility_ratio": c["visibility"]["median"],
            "cpu_shaded_ratio": c["shaded"]["median"], "agreement": agree,
            "renderer": r["renderer"]}


def verdict(row, pixels):
    """One line per view: the target met (wall and CPU time), or by how much it is missed and
    what the measurement says stands in the way."""
    slow = [k for k in ("visibility", "shaded")
            if row[k + "_ratio"] < TARGET or row["cpu_" + k + "_ratio"] < TARGET]
    if not slow:
        return "%s: step 06 at least as fast as llvmpipe (target met)" % row["mesh"]
    parts = ["%s takes %.2fx llvmpipe's time (CPU time %.2fx)"
             % (k, 1 / row[k + "_ratio"], 1 / row["cpu_" + k + "_ratio"]) for k in slow]
    ns = 1e6 * row["step06_no_culling_ms"] / max(1, row["fragments"])
    culling = ""
    if row["no_culling_ratio"] > row["visibility_ratio"]:
        culling = ("; the frustum culling costs more than it saves here (without it, "
                   "visibility at x%.2f)" % row["no_culling_ratio"])
    return ("%s: target missed: step 06 %s. In the way: the work per pixel centre covered "
            "(%d of them, %.1f per pixel; %.0f ns each in the unculled frame: per fragment a "
            "division for its depth and the exercise's depthTest, per visible "
            "pixel the perspective-correct weights in double precision, one pixel at a "
            "time), where llvmpipe tests and writes 4x4 blocks of fragments with SIMD in "
            "JIT-compiled code; culling kept %d of %d triangles%s"
            % (row["mesh"], " and ".join(parts), row["fragments"], row["fragments"] / pixels,
               ns, row["triangles_after_culling"], row["triangles"], culling))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", default="bunny,oa_thor")
    ap.add_argument("--width", type=int, default=640)
    ap.add_argument("--height", type=int, default=480)
    ap.add_argument("--repeat", type=int, default=5, help="frames per variant and round (median)")
    ap.add_argument("--rounds", type=int, default=5, help="rounds of every variant, in turn")
    ap.add_argument("--data", default=os.environ.get("BOXES_MESHES") or None,
                    help="read MESH.obj from this folder instead (default $BOXES_MESHES)")
    ap.add_argument("--cache", default=os.path.join(ROOT, "build", "meshes"),
                    help="where meshes converted from Debian packages are kept")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "06_raster_bench.json"))
    ap.add_argument("--program", default=os.path.join(ROOT, "build/release/tools/bench/raster_gl"))
    a = ap.parse_args(argv)
    if not os.access(a.program, os.X_OK):
        raise SystemExit("bench06: no raster_gl at %s: ./workbook bench builds it" % a.program)
    rows, unavailable = [], []
    for mesh in a.meshes.split(","):
        try:
            obj = meshes.mesh_path(mesh, a.cache, a.data)
        except meshes.Unavailable as e:
            unavailable.append(str(e))
            print("bench06: left out: %s" % e, file=sys.stderr)
            continue
        r = run_view(a, mesh, obj)
        row = row_of(mesh, r)
        for key in ("visibility_ratio", "shaded_ratio"):
            if not (math.isfinite(row[key]) and row[key] > 0):
                raise SystemExit("bench06: %s: a ratio that is no positive number" % mesh)
        rows.append(row)
        print("%-8s visibility x%.2f  shaded x%.2f  agree %.4f" % (
            mesh, row["visibility_ratio"], row["shaded_ratio"], row["agreement"]), file=sys.stderr)
    if not rows:
        raise SystemExit("bench06: none of the meshes %s can be had" % a.meshes)

    print("\nStep 06 beside Mesa's llvmpipe (%s; LP_NUM_THREADS=%s), %dx%d, the same triangles "
          "and camera; %d rounds, each the median of %d frames; ratio: llvmpipe's time over "
          "step 06's (above 1: step 06 faster), the median of the rounds' ratios"
          % (rows[0]["renderer"], os.environ.get("LP_NUM_THREADS", "1"), a.width, a.height,
             a.rounds, a.repeat))
    print("%-8s %8s %9s %9s %7s %9s %9s %7s %9s %9s %8s" % (
        "mesh", "tris", "ours vis", "llvm vis", "ratio", "ours shd", "llvm shd", "ratio",
        "CPU vis", "CPU shd", "agree"))
    for r in rows:
        print("%-8s %8d %7.1fms %7.1fms %7.2f %7.1fms %7.1fms %7.2f %9.2f %9.2f %8.4f" % (
            r["mesh"], r["triangles"], r["step06_visibility_ms"], r["llvmpipe_visibility_ms"],
            r["visibility_ratio"], r["step06_shaded_ms"], r["llvmpipe_shaded_ms"],
            r["shaded_ratio"], r["cpu_visibility_ratio"], r["cpu_shaded_ratio"], r["agreement"]))
    print("\nBeside them: step 06 without frustum culling, and llvmpipe with the depth buffer "
          "only (no triangle written):")
    for r in rows:
        print("  %-8s no culling x%.2f (%.1f ms)   against llvmpipe depth only x%.2f (%.1f ms)" % (
            r["mesh"], r["no_culling_ratio"], r["step06_no_culling_ms"], r["depth_only_ratio"],
            r["llvmpipe_depth_only_ms"]))
    print("")
    for r in rows:
        print(verdict(r, a.width * a.height))
        if r["agreement"] < AGREEMENT:
            print("%s: the same triangle at only %.2f%% of the covered pixels (target %.1f%%)"
                  % (r["mesh"], 100 * r["agreement"], 100 * AGREEMENT))
    for line in unavailable:
        print("Left out: %s" % line)
    load = os.getloadavg()[0]
    print("(load average during the run: %.1f on %d cores)" % (load, os.cpu_count()))
    report = {"program": "06_raster_bench", "images": [], "facts": {"load_average": load},
              "machine": machine.describe(load),
              "width": a.width, "height": a.height, "rounds": a.rounds, "repeat": a.repeat,
              "unavailable": unavailable, "rows": rows,
              "tables": [{
                  "id": "bench06_llvmpipe", "title": "Step 06 beside Mesa's llvmpipe, one thread",
                  "columns": ["mesh", "triangles", "step 06 visibility ms",
                              "llvmpipe visibility ms", "visibility ratio", "step 06 shaded ms",
                              "llvmpipe shaded ms", "shaded ratio", "same triangle"],
                  "rows": [[r["mesh"], r["triangles"], r["step06_visibility_ms"],
                            r["llvmpipe_visibility_ms"], r["visibility_ratio"],
                            r["step06_shaded_ms"], r["llvmpipe_shaded_ms"], r["shaded_ratio"],
                            r["agreement"]] for r in rows],
                  "note": "%dx%d; ratio: llvmpipe's time over step 06's (above 1: step 06 "
                          "faster), the median of %d rounds' ratios, each the median of %d "
                          "frames" % (a.width, a.height, a.rounds, a.repeat)}]}
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    with open(a.out, "w") as f:
        json.dump(report, f, indent=1)
    print("wrote " + a.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
