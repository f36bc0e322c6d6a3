#!/usr/bin/python3
"""Step 04 beside Intel Embree: the same rays, back to back, one thread each.

usage: python3 -m tools.bench.bench04 [--rays N] [--repeat K] [--rounds R]
                        [--meshes bunny,motorbike,oa_thor] [--kinds primary,diffuse,random]
                        [--builders midpoint,median,sah,sah4,sah8,sbvh,sbvh4,sbvh8]
                        [--no-extras] [--thread-rays N] [--thread-pairs P] [--quiet-wait S]
                        [--out out/04_bvh_bench.json] [--program PATH] [--embree PATH]
                        [--cache DIR] [--data DIR | BOXES_MESHES=DIR]
       (./workbook bench ...)

For every mesh and ray kind (primary, diffuse, random) it writes one ray set with
`04_bvh rays`, runs the workbook's Embree harness (tools/bench/embree_trace: Embree 3,
`rtcIntersect1`, one thread) and then our
`04_bvh trace` with each builder on that file (and "sah 4-wide", "sah 8-wide": the
binned SAH tree collapsed to 4- or 8-wide nodes, `--width 4` or `--width 8`; "sbvh",
"sbvh 4-wide" and "sbvh 8-wide": the binned SAH with spatial splits, not an exercise), each run
--repeat passes (the programs report the median), all of it --rounds times, alternating;
the ratios are the medians of the rounds' own ratios. Each round first waits (at most
--quiet-wait s) until a short probe runs at 90% of its best speed: on a shared machine some
minutes run memory-bound code 30-40% slower. It compares the hits ray by ray with Embree's.
The interior map (oa_thor) gets its primary rays from a camera inside it. Also: binned SAH on
2 threads against 1 beside Embree's own two-thread speed-up (larger ray sets, alternating
pairs), and the full-sweep SAH cost (the quality reference). Prints the
table builder x ray kind x mesh and writes it as JSON (for the report).
Needs what `./workbook bench` installs and builds: libembree-dev and openfoam-examples
(tools/deps.sh bench), 04_bvh and embree_trace in the release build. The meshes
(tools/bench/meshes.py): the bunny from data/meshes/, the motorbike converted on first use
from openfoam-examples into --cache (default build/meshes/); a mesh that cannot be had is
left out with one line saying why. --data DIR (or BOXES_MESHES) reads MESH.obj from DIR
instead.
"""
import argparse
import json
import os
import re
import signal
import statistics
import struct
import subprocess
import sys
import tempfile
import time

from .. import ROOT
from . import machine, meshes
INSIDE = ["--eye", "960,-384,2", "--look", "960,600,2", "--up", "0,0,1", "--fov", "90"]


def make_rays(program, obj, kind, count, out, extra=()):
    """A ray set from `04_bvh rays` (extra: its camera options, a seed)."""
    subprocess.run([program, "rays", "--mesh", obj, "--kind", kind, "--count", str(count),
                    "--out", out] + list(extra), check=True, capture_output=True)


def run_json(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def embree_tree_sah(embree, obj, rays, work):
    """The SAH cost Embree prints for the tree it traces (verbose=3: each node its area, each
    leaf its area times its blocks of four, over the root's; the last build is the traced
    one), from one traced ray. None when its output has no such line."""
    one = os.path.join(work, "one-ray.bin")
    with open(rays, "rb") as f, open(one, "wb") as g:
        g.write(f.read(32))
    out = subprocess.run([embree, "--mesh", obj, "--rays", one, "--hits",
                          os.path.join(work, "one-hit.bin"), "--config", "verbose=3"],
                         capture_output=True, text=True)
    costs = re.findall(r"total\s*: sah =\s*([0-9.]+)", out.stdout + out.stderr)
    return float(costs[-1]) if costs else None


def run_ours(cmd, repeat):
    """Our trace and embree_trace report the CPU time of their trace passes themselves
    (trace_cpu_ms, median): on a loaded machine the wall time mostly measures the scheduler;
    CPU time does not (though the cache still suffers from the neighbours)."""
    j = run_json(cmd + ["--repeat", str(repeat)])
    j["mrays_per_cpu_s"] = j["rays"] / max(1e-9, j["trace_cpu_ms"] / 1e3) / 1e6
    return j


class QuietGate:
    """Waits, before each round, for a minute in which memory-bound code runs at its usual
    speed. On a shared machine some minutes run memory-bound code 30-40% slower (Embree too,
    ours more) while the load average shows nothing; a round measured in one spoils its
    ratios. The probe: our 8-wide tree on 100,000 diffuse rays of the bunny (about 0.3 s);
    a round starts once the probe reaches 90% of the best it reached in this run, or after
    --quiet-wait seconds."""

    def __init__(self, a, obj, work):
        self.cmd, self.best, self.waited, self.max_wait = None, 0.0, 0.0, a.quiet_wait
        if a.quiet_wait <= 0:
            return
        rays = os.path.join(work, "probe.bin")
        make_rays(a.program, obj, "diffuse", 100000, rays, ["--seed", "11"])
        self.cmd = [a.program, "trace", "--mesh", obj, "--rays", rays, "--hits",
                    os.path.join(work, "probe-hits.bin"), "--width", "8", "--repeat", "3"]
        for _ in range(3):  # a first reference
            self.probe()

    def probe(self):
        speed = run_json(self.cmd)["mrays_per_s"]
        self.best = max(self.best, speed)
        return speed

    def wait(self):
        if self.cmd is None:
            return
        start = time.monotonic()
        while True:
            speed = self.probe()
            if speed >= 0.9 * self.best:
                break
            waited = time.monotonic() - start
            if waited >= self.max_wait:
                print("  (the machine stayed slow: probe at %.0f%% of its best after %.0f s; "
                      "measuring anyway)" % (100 * speed / self.best, waited), file=sys.stderr)
                break
            print("  waiting for a quiet minute: probe at %.0f%% of its best" %
                  (100 * speed / self.best), file=sys.stderr)
            time.sleep(5)
        self.waited += time.monotonic() - start


def round_ratios(ours, theirs, key):
    """Per round, ours[key] / theirs[key], lowest first (ours and theirs: one run per round)."""
    return sorted(o[key] / t[key] for o, t in zip(ours, theirs))


def read_hits(path):
    with open(path, "rb") as f:
        data = f.read()
    return [struct.unpack_from("<fI", data, 8 * i) for i in range(len(data) // 8)]


def agreement(ours, theirs):
    same = sum(1 for a, b in zip(ours, theirs) if a[1] == b[1] or a[0] == b[0])
    return same / max(1, len(ours))


def measure_threads(a, obj, mesh, kind, work, gate):
    """Two threads against one on a larger ray set (--thread-rays: a pass must last long
    enough that starting the threads and the scheduler's noise do not count), in alternating
    pairs, ours (binned SAH) and Embree's; the medians of the pairs' speed-ups. Each pair
    waits for a quiet minute first, as the rounds do. Embree's speed-up beside ours is not
    the machine's ceiling: embree_trace starts its threads for every pass."""
    rays = os.path.join(work, "%s-%s-threads.bin" % (mesh, kind))
    extra = INSIDE if (mesh == "oa_thor" and kind == "primary") else []
    make_rays(a.program, obj, kind, a.thread_rays, rays, ["--seed", "7"] + extra)
    hits = os.path.join(work, "threads-hits.bin")
    speed = {"ours": {1: [], 2: []}, "embree": {1: [], 2: []}}
    for _ in range(a.thread_pairs):
        gate.wait()
        for n in (1, 2):
            speed["ours"][n].append(run_json(
                [a.program, "trace", "--mesh", obj, "--rays", rays, "--hits", hits, "--threads",
                 str(n), "--repeat", str(a.repeat)])["mrays_per_s"])
            speed["embree"][n].append(run_json(
                [a.embree, "--mesh", obj, "--rays", rays, "--hits", hits, "--threads", str(n), "--repeat",
                 str(a.repeat)])["mrays_per_s"])

    def speedup(who):
        return statistics.median([b / o for o, b in zip(speed[who][1], speed[who][2])])

    t = {"mesh": mesh, "kind": kind, "rays": a.thread_rays,
         "one": statistics.median(speed["ours"][1]), "two": statistics.median(speed["ours"][2]),
         "speedup": speedup("ours"),
         "embree_speedup": speedup("embree")}
    print("%-9s %-8s threads: ours 1: %.3f  2: %.3f Mrays/s  speed-up %.2fx (Embree's %.2fx)"
          % (mesh, kind, t["one"], t["two"], t["speedup"], t["embree_speedup"]), file=sys.stderr)
    return t


# The engine's targets, one thread unless named (the advanced README has their table):
# (what, builders whose best counts, ray kind, the least ratio to Embree on every mesh).
TARGETS = [("best 8-wide tree, primary rays", ("sah 8-wide", "sbvh 8-wide"), "primary", 1.3),
           ("best 8-wide tree, diffuse rays", ("sah 8-wide", "sbvh 8-wide"), "diffuse", 1.0),
           ("binary SAH tree (the exercises'), primary rays", ("sah",), "primary", 0.75)]
TWO_THREADS = 1.9


def target_lines(rows, threads):
    """Each target met, or missed by how much on its worst mesh, with the ratio per mesh."""
    ratio = {(r["builder"], r["mesh"], r["kind"]): r["ratio"] for r in rows}
    meshes = list(dict.fromkeys(r["mesh"] for r in rows))

    def verdict(cells, goal):
        worst = min(v for _, v in cells)
        met = "met" if worst >= goal else "missed by %.0f%%" % (100 * (1 - worst / goal))
        return "%s (%s)" % (met, ", ".join("%s %.2fx" % c for c in cells))
    lines = []
    for what, builders, kind, goal in TARGETS:
        cells = [(m, max(ratio[(b, m, kind)] for b in builders if (b, m, kind) in ratio))
                 for m in meshes if any((b, m, kind) in ratio for b in builders)]
        if cells:
            lines.append("  %-48s >= %.2fx: %s" % (what, goal, verdict(cells, goal)))
    cells = [("%s %s" % (t["mesh"], t["kind"]), t["speedup"]) for t in threads]
    if cells:
        lines.append("  %-48s >= %.2fx: %s" % ("two threads against one (binary SAH)",
                                               TWO_THREADS, verdict(cells, TWO_THREADS)))
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rays", type=int, default=250000)
    ap.add_argument("--repeat", type=int, default=5, help="trace passes per run (its median)")
    ap.add_argument("--rounds", type=int, default=3,
                    help="runs of Embree and every builder, alternating (medians of the ratios)")
    ap.add_argument("--meshes", default="bunny,motorbike,oa_thor")
    ap.add_argument("--kinds", default="primary,diffuse,random")
    ap.add_argument("--builders", default="midpoint,median,sah,sah4,sah8,sbvh,sbvh4,sbvh8",
                    help="sah4, sah8, sbvh4, sbvh8: the tree collapsed to 4- or 8-wide nodes (SIMD)")
    ap.add_argument("--no-extras", action="store_true",
                    help="skip the two-thread runs and the sweep-SAH quality reference")
    ap.add_argument("--thread-rays", type=int, default=500000,
                    help="rays per set for the two-thread row (primary and diffuse)")
    ap.add_argument("--thread-pairs", type=int, default=5,
                    help="alternating 1-thread/2-thread pairs for the two-thread row")
    ap.add_argument("--data", default=os.environ.get("BOXES_MESHES") or None,
                    help="read MESH.obj from this folder instead (default $BOXES_MESHES; "
                         "unset: the shipped and converted meshes)")
    ap.add_argument("--cache", default=os.path.join(ROOT, "build", "meshes"),
                    help="where meshes converted from Debian packages are kept")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "04_bvh_bench.json"))
    ap.add_argument("--program", default=os.path.join(ROOT, "build/release/steps/04_bvh/04_bvh"))
    ap.add_argument("--embree", default=os.path.join(ROOT, "build/release/tools/bench/embree_trace"),
                    help="the Embree harness (tools/bench/embree_trace.cpp)")
    ap.add_argument("--quiet-wait", type=float, default=60,
                    help="seconds a round may wait for a quiet minute (0: no probe, no wait)")
    a = ap.parse_args()
    for path, what in ((a.program, "04_bvh"), (a.embree, "embree_trace")):
        if not os.access(path, os.X_OK):
            raise SystemExit(f"bench04: no {what} at {path}: ./workbook bench builds it (Embree's "
                             "harness needs libembree-dev: tools/deps.sh bench)")

    # A private scratch folder, removed however the run ends (Ctrl-C, SIGTERM, a failure).
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    with tempfile.TemporaryDirectory(prefix="boxes-bench04-") as work:
        bench(a, work)


def bench(a, work):
    objs, unavailable = {}, []
    for mesh in a.meshes.split(","):
        try:
            objs[mesh] = meshes.mesh_path(mesh, a.cache, a.data)
        except meshes.Unavailable as e:
            unavailable.append(str(e))
            print("bench04: left out: %s" % e, file=sys.stderr)
    if not objs:
        raise SystemExit("bench04: none of the meshes %s can be had" % a.meshes)
    a.meshes = ",".join(objs)
    gate = QuietGate(a, objs.get("bunny", next(iter(objs.values()))), work)
    rows, threads, quality, tree_sah = [], [], [], {}
    for mesh, obj in objs.items():
        sweep = None
        for kind in a.kinds.split(","):
            rays = os.path.join(work, "%s-%s.bin" % (mesh, kind))
            extra = INSIDE if (mesh == "oa_thor" and kind == "primary") else []
            make_rays(a.program, obj, kind, a.rays, rays, extra)
            # Rounds: Embree, then every builder, again and again; each ratio is the median
            # of the rounds' own ratios, so a burst of load on a shared machine spoils one
            # round, not the comparison (a single run drifts by 10-20%).
            # (row name, --builders name, trace options); "sah 4-wide", "sah 8-wide": the
            # binned SAH tree collapsed to 4- or 8-wide nodes, SIMD traversal.
            variants = [(b, args) for b, key, args in (
                ("midpoint", "midpoint", ["--builder", "midpoint"]),
                ("median", "median", ["--builder", "median"]),
                ("sah", "sah", ["--builder", "sah"]),
                ("sah 4-wide", "sah4", ["--builder", "sah", "--width", "4"]),
                ("sah 8-wide", "sah8", ["--builder", "sah", "--width", "8"]),
                ("sbvh", "sbvh", ["--builder", "sbvh"]),
                ("sbvh 4-wide", "sbvh4", ["--builder", "sbvh", "--width", "4"]),
                ("sbvh 8-wide", "sbvh8", ["--builder", "sbvh", "--width", "8"]))
                if key in a.builders.split(",")]
            ehits, ohits = os.path.join(work, "embree.bin"), os.path.join(work, "ours.bin")
            embree_runs, our_runs, agree = [], {b: [] for b, _ in variants}, {}
            for round_index in range(a.rounds):
                gate.wait()
                embree_runs.append(run_ours([a.embree, "--mesh", obj, "--rays", rays, "--hits",
                                             ehits, "--threads", "1"], a.repeat))
                eh = read_hits(ehits) if round_index == 0 else None
                for builder, args in variants:
                    our_runs[builder].append(run_ours(
                        [a.program, "trace", "--mesh", obj, "--rays", rays, "--hits", ohits,
                         "--threads", "1"] + args, a.repeat))
                    if eh is not None:
                        agree[builder] = agreement(read_hits(ohits), eh)
            for builder, _ in variants:
                runs = our_runs[builder]

                def med(key, of=runs):
                    return statistics.median(r[key] for r in of)

                # The rounds' own ratios; a wide range says the machine was noisy while this
                # row ran (trust the median less).
                ratios = round_ratios(runs, embree_runs, "mrays_per_s")
                row = {"mesh": mesh, "kind": kind, "builder": builder,
                       "mrays_per_s": med("mrays_per_s"),
                       "embree_mrays_per_s": med("mrays_per_s", embree_runs),
                       "ratio": statistics.median(ratios), "ratio_range": [ratios[0], ratios[-1]],
                       "cpu_mrays_per_s": med("mrays_per_cpu_s"),
                       "embree_cpu_mrays_per_s": med("mrays_per_cpu_s", embree_runs),
                       "cpu_ratio": statistics.median(
                           round_ratios(runs, embree_runs, "mrays_per_cpu_s")),
                       "build_cpu_ms": med("build_cpu_ms"), "build_ms": med("build_ms"),
                       "embree_build_ms": med("build_ms", embree_runs),
                       "sah_cost": runs[0]["sah_cost"], "tris": runs[0]["tris"],
                       "rays": runs[0]["rays"], "agree_with_embree": agree[builder],
                       "runs": runs}
                rows.append(row)
                print("%-9s %-8s %-10s %7.3f Mrays/s  x%.2f Embree (rounds %.2f-%.2f; CPU time: "
                      "x%.2f)  build %8.1f ms  SAH %.2f  agree %.4f"
                      % (mesh, kind, builder, row["mrays_per_s"], row["ratio"], ratios[0],
                         ratios[-1], row["cpu_ratio"], row["build_ms"], row["sah_cost"],
                         row["agree_with_embree"]), file=sys.stderr)
            if kind in ("primary", "diffuse") and not a.no_extras:
                threads.append(measure_threads(a, obj, mesh, kind, work, gate))
            if mesh not in tree_sah and not a.no_extras:
                ours = {r["builder"]: r["runs"][0].get("sah_cost_8wide") for r in rows
                        if r["mesh"] == mesh and r["builder"] in ("sah 8-wide", "sbvh 8-wide")}
                tree_sah[mesh] = {"embree": embree_tree_sah(a.embree, obj, rays, work),
                                  "sah8": ours.get("sah 8-wide"), "sbvh8": ours.get("sbvh 8-wide")}
            if sweep is None and not a.no_extras:
                sweep = run_json([a.program, "trace", "--mesh", obj, "--rays", rays, "--hits", ohits,
                                  "--builder", "sweep-sah"])
                sah = [r for r in rows if r["mesh"] == mesh and r["builder"] == "sah"]
                if not sah:
                    continue
                sah = sah[0]
                quality.append({"mesh": mesh, "tris": sah["tris"], "bins": sah["runs"][0]["bins"],
                                "sah_cost": sah["sah_cost"],
                                "sweep_sah_cost": sweep["sah_cost"],
                                "excess_pct": 100.0 * (sah["sah_cost"] / sweep["sah_cost"] - 1.0),
                                "build_ms": sah["build_ms"],
                                "s_per_mtri": sah["build_ms"] / 1e3 / (sah["tris"] / 1e6),
                                "cpu_s_per_mtri": sah["build_cpu_ms"] / 1e3 / (sah["tris"] / 1e6)})

    print("\nStep 04 beside Embree 3 (one thread each, %d rays per set; %d rounds of Embree "
          "and each builder, each run the median of %d passes; Mrays/s the median of the "
          "rounds, ratio the median of the rounds' ratios)" % (a.rays, a.rounds, a.repeat))
    print("%-10s %-8s %-10s %9s %9s %7s %11s %9s %10s %9s %8s" % (
        "mesh", "rays", "builder", "Mrays/s", "Embree", "ratio", "rounds", "CPU ratio", "build ms",
        "SAH cost", "agree"))
    for r in rows:
        print("%-10s %-8s %-10s %9.3f %9.3f %7.3f %5.2f-%5.2f %9.3f %10.1f %9.2f %8.4f" % (
            r["mesh"], r["kind"], r["builder"], r["mrays_per_s"], r["embree_mrays_per_s"],
            r["ratio"], r["ratio_range"][0], r["ratio_range"][1], r["cpu_ratio"], r["build_ms"],
            r["sah_cost"], r["agree_with_embree"]))

    def paired(a_row, b_row, key):  # two builders: the median of the rounds' own ratios
        return statistics.median(round_ratios(a_row["runs"], b_row["runs"], key))

    for sah in ("sah", "sbvh"):
        print("\n%s against midpoint (primary rays; wall, CPU time; medians of the rounds):"
              % ("Binned SAH" if sah == "sah" else "SAH with spatial splits"))
        for mesh in a.meshes.split(","):
            by = {r["builder"]: r for r in rows if r["mesh"] == mesh and r["kind"] == "primary"}
            if sah not in by or "midpoint" not in by:
                continue
            print("  %-10s %.2fx  %.2fx" % (mesh, paired(by[sah], by["midpoint"], "mrays_per_s"),
                                            paired(by[sah], by["midpoint"], "mrays_per_cpu_s")))
    print("\nSpatial splits against the binned SAH (same width; wall, CPU time):")
    for plain, split in (("sah", "sbvh"), ("sah 4-wide", "sbvh 4-wide"),
                         ("sah 8-wide", "sbvh 8-wide")):
        for mesh in a.meshes.split(","):
            for kind in a.kinds.split(","):
                by = {r["builder"]: r for r in rows if r["mesh"] == mesh and r["kind"] == kind}
                if plain not in by or split not in by:
                    continue
                print("  %-11s %-10s %-8s %.2fx  %.2fx" % (
                    split, mesh, kind, paired(by[split], by[plain], "mrays_per_s"),
                    paired(by[split], by[plain], "mrays_per_cpu_s")))
    for wide in ("sah 4-wide", "sah 8-wide"):
        print("\n%s (SIMD) against the binary tree, binned SAH (wall, CPU time):" % wide[4:])
        for mesh in a.meshes.split(","):
            for kind in a.kinds.split(","):
                by = {r["builder"]: r for r in rows if r["mesh"] == mesh and r["kind"] == kind}
                if "sah" not in by or wide not in by:
                    continue
                print("  %-10s %-8s %.2fx  %.2fx" % (
                    mesh, kind, paired(by[wide], by["sah"], "mrays_per_s"),
                    paired(by[wide], by["sah"], "mrays_per_cpu_s")))
    bins = sorted({q["bins"] for q in quality})
    print("\nBuild and quality (binned SAH, %s bins, one thread):" % "/".join(map(str, bins)))
    for q in quality:
        print("  %-10s %8d tris  %7.1f ms  %.3f s/Mtri (CPU %.3f)  SAH %.2f vs sweep %.2f "
              "(+%.2f%%)" % (q["mesh"], q["tris"], q["build_ms"], q["s_per_mtri"],
                            q["cpu_s_per_mtri"], q["sah_cost"], q["sweep_sah_cost"],
                            q["excess_pct"]))
    print("\nTree quality in the units of Embree's statistics (8-wide: each node its area, "
          "each leaf its area times its packets or blocks, over the root's; lower is better):")
    for mesh, t in tree_sah.items():
        print("  %-10s Embree %s  sah 8-wide %s  sbvh 8-wide %s" % (
            mesh, *("%.2f" % v if v is not None else "-" for v in
                    (t["embree"], t["sah8"], t["sbvh8"]))))
    print("\nTwo threads against one (binned SAH; %d rays per set, medians of %d alternating "
          "pairs; Embree's own speed-up on the same rays beside it, its threads started for "
          "every pass by embree_trace):" % (a.thread_rays, a.thread_pairs))
    for t in threads:
        print("  %-10s %-8s 1: %.3f  2: %.3f  speed-up %.2fx  (Embree %.2fx)" % (
            t["mesh"], t["kind"], t["one"], t["two"], t["speedup"], t["embree_speedup"]))
    print("\nThe targets (ratios to Embree on every mesh; the advanced README has their table):")
    for line in target_lines(rows, threads):
        print(line)
    for line in unavailable:
        print("\nLeft out: %s" % line)
    load = os.getloadavg()[0]
    print("\n(load average during the run: %.1f on %d cores; ratios are back to back, the "
          "absolute figures drift with the load; %.0f s spent waiting for quiet minutes)"
          % (load, os.cpu_count(), gate.waited))
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    # The ratios at a glance (the report's and the deck's summary): builders down, ray sets
    # across.
    sets = [(m, k) for m in a.meshes.split(",") for k in a.kinds.split(",")
            if any(r["mesh"] == m and r["kind"] == k for r in rows)]
    builders = list(dict.fromkeys(r["builder"] for r in rows))
    ratio_of = {(r["builder"], r["mesh"], r["kind"]): round(r["ratio"], 2) for r in rows}
    ratios_table = {
        "id": "bench04_ratios", "title": "Rays per second against Embree's (one thread each)",
        "columns": ["builder"] + ["%s %s" % (m, k) for m, k in sets],
        "rows": [[b] + [ratio_of.get((b, m, k)) for m, k in sets] for b in builders],
        "note": "Per cell the median of the rounds' ratios (%d rounds; the Mrays/s are in "
                "bench04_embree). The targets: the best 8-wide tree at least 1.3 on primary "
                "and 1.0 on diffuse rays, the binary SAH tree ('sah') 0.75 on primary rays"
                % a.rounds}
    report = {"program": "04_bvh_bench", "images": [],
              "machine": machine.describe(load), "facts": {"load_average": os.getloadavg()[0]},
              "rays": a.rays, "repeat": a.repeat, "load_average": load,
              "quiet_wait_s": gate.waited, "unavailable": unavailable,
              "tables": [
                  ratios_table,
                  {"id": "bench04_embree", "title": "Step 04 beside Embree 3: one thread each",
                   "columns": ["mesh", "rays", "builder", "Mrays/s", "Embree Mrays/s", "ratio",
                               "CPU ratio", "build ms", "SAH cost", "agree"],
                   "rows": [[r["mesh"], r["kind"], r["builder"], r["mrays_per_s"],
                             r["embree_mrays_per_s"], r["ratio"], r["cpu_ratio"], r["build_ms"],
                             r["sah_cost"], r["agree_with_embree"]] for r in rows],
                   "note": "%d rounds of Embree then each builder on the same ray file, each "
                           "run the median of %d passes; Mrays/s the median of the rounds; "
                           "'ratio' (the median of the rounds' ratios) "
                           "from wall times, 'CPU ratio' from the CPU seconds of a trace pass "
                           "(each program measures its own passes; steadier on a loaded machine); "
                           "'agree': share of rays with Embree's triangle or t; "
                           "each round began once a probe ran at 90%% of its best speed (%.0f s "
                           "of waiting in all, at most %.0f s per round)"
                           % (a.rounds, a.repeat, gate.waited, a.quiet_wait)},
                  {"id": "bench04_build", "title": "Binned SAH build: time and quality",
                   "columns": ["mesh", "tris", "build ms", "s/Mtri", "CPU s/Mtri", "SAH cost",
                               "sweep SAH cost", "excess %"],
                   "rows": [[q["mesh"], q["tris"], q["build_ms"], q["s_per_mtri"],
                             q["cpu_s_per_mtri"], q["sah_cost"], q["sweep_sah_cost"],
                             q["excess_pct"]] for q in quality], "note": ""},
                  {"id": "bench04_tree_sah",
                   "title": "Tree quality beside Embree's, in its statistics' units",
                   "columns": ["mesh", "Embree", "sah 8-wide", "sbvh 8-wide"],
                   "rows": [[m, t["embree"], t["sah8"], t["sbvh8"]]
                            for m, t in tree_sah.items()],
                   "note": "The SAH cost Embree prints for its traced tree (embree_trace --config "
                           "verbose=3: each 8-wide node its area, each leaf its area times its "
                           "blocks of four triangles, over the root's area) and ours in the same "
                           "units (trace --width 8: sah_cost_8wide, packets for blocks); lower "
                           "is better"},
                  {"id": "bench04_threads", "title": "Two threads against one (binned SAH)",
                   "columns": ["mesh", "rays", "1 thread", "2 threads", "speed-up",
                               "Embree speed-up"],
                   "rows": [[t["mesh"], t["kind"], t["one"], t["two"], t["speedup"],
                             t["embree_speedup"]] for t in threads],
                   "note": "Mrays/s; %d rays per set, medians of %d alternating 1/2-thread "
                           "pairs; ours keeps its worker threads between passes; embree_trace "
                           "starts Embree's threads for every pass while its main thread "
                           "waits, which held our tracer to 1.0-1.2x on short passes, so "
                           "Embree's speed-up beside ours is not the machine's ceiling"
                           % (a.thread_rays, a.thread_pairs)},
                  {"id": "bench04_tradeoff", "title": "Build time against trace speed",
                   "columns": ["builder", "mesh", "build ms", "Mrays/s"],
                   "rows": [[r["builder"], r["mesh"], r["build_ms"], r["mrays_per_s"]]
                            for r in rows if r["kind"] == "primary"], "note": "primary rays"}],
              "plots": [{"table": "bench04_tradeoff", "x": "build ms", "y": "Mrays/s",
                         "series": "builder", "point_label": "mesh", "logx": True,
                         "title": "Builders: build time against trace speed (primary rays)"}]}
    with open(a.out, "w") as f:
        json.dump(report, f, indent=1)
    print("wrote " + a.out)


if __name__ == "__main__":
    main()
