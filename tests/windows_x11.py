#!/usr/bin/python3
"""Every step's window on a real X server (Xvfb): the X11 and GLX path a student's desktop
takes, beside the offscreen driver (EGL) that the doctest window cases use.

usage: tests/windows_x11.py BUILD_DIR PNG_COMPARE
Each step program runs the same scripted frames and keys twice, once under xvfb-run with
SDL_VIDEODRIVER=x11 (no fallback to another driver) and once with SDL_VIDEODRIVER=offscreen,
and writes a screenshot each time. Checked: both exit 0; the X11 window has the default
size (960 x 720) and shows a picture (at least 200 distinct colours; a blank framebuffer
has one); and it is the offscreen window's picture: at most 1% of the pixels differ by
more than one 8-bit step (the panel's timings, such as "46.6 ms/frame", differ from run to
run). Exit 77 (ctest: skipped) without xvfb-run (tools/deps.sh test).
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# Every step folder of the tree; a step whose program was not built is a failure.
STEPS = sorted(d for d in os.listdir(os.path.join(ROOT, "steps")) if d[:2].isdigit())
# Orbit and move, which every step has. Step 05 first picks the full render for every frame
# ("0"): its default preview adapts the resolution to the frame time, which differs by run.
KEYS = {"05_efficiency": "0,Left,W,Up"}
# Step 05 refines lines of pixels within a time budget per frame: with the default 15 ms a
# loaded machine shows a half-refined frame (and its progress bar) in one run and not the
# other. A budget of a second finishes every 160 x 120 frame at once in both.
EXTRA = {"05_efficiency": ["--budget-ms", "1000"]}
DEFAULT_KEYS = "Left,W,Up"
WINDOW = (960, 720)  # core/window.hpp's default size
MIN_COLOURS = 200
MAX_DIFFERING = 0.01


def screenshot(program, keys, extra, driver, shot, work):
    """Runs the scripted window with the driver; None when it worked, else why not."""
    env = dict(os.environ, SDL_VIDEODRIVER=driver, ASAN_OPTIONS="detect_leaks=0")
    # A small image keeps the frames quick; the window keeps its size, the image scaled.
    cmd = [program, "--width", "160", "--height", "120", "--frames", "6", "--keys", keys,
           "--screenshot", shot] + extra
    if driver == "x11":
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24"] + cmd
    try:
        run = subprocess.run(cmd, env=env, cwd=work, capture_output=True, text=True, timeout=240)
    except subprocess.TimeoutExpired:
        return f"{driver}: no exit within 240 s"
    if run.returncode != 0 or not os.path.exists(shot):
        return f"{driver}: exit {run.returncode}, {run.stderr.strip()[-300:]}"
    return None


def main():
    if len(sys.argv) != 3:
        print("usage: tests/windows_x11.py BUILD_DIR PNG_COMPARE")
        return 2
    build, compare = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    if not shutil.which("xvfb-run"):
        print("SKIP: no xvfb-run (tools/deps.sh test)")
        return 77
    failures = 0
    with tempfile.TemporaryDirectory() as work:
        for step in STEPS:
            program = os.path.join(build, "steps", step, step)
            if not os.path.exists(program):
                print(f"FAIL  {step}: no program {program}")
                failures += 1
                continue
            x11, offscreen = (os.path.join(work, f"{step}-{d}.png") for d in ("x11", "offscreen"))
            keys = KEYS.get(step, DEFAULT_KEYS)
            extra = EXTRA.get(step, [])
            problem = screenshot(program, keys, extra, "x11", x11, work) or \
                screenshot(program, keys, extra, "offscreen", offscreen, work)
            if not problem:
                out = subprocess.run([compare, x11, offscreen], capture_output=True, text=True)
                if out.returncode != 0:
                    problem = out.stderr.strip()
                else:
                    c = json.loads(out.stdout)
                    size = (c["width"], c["height"])
                    if size != WINDOW:
                        problem = f"the window is {size}, not {WINDOW}"
                    elif c["distinct_colours"] < MIN_COLOURS:
                        problem = f"a blank window: {c['distinct_colours']} colours"
                    elif c["differing"] > MAX_DIFFERING:
                        problem = f"{100 * c['differing']:.2f}% of the pixels differ from offscreen"
            if problem:
                print(f"FAIL  {step}: {problem}")
                failures += 1
            else:
                print(f"ok    {step}: {c['distinct_colours']} colours, "
                      f"{100 * c['differing']:.2f}% of the pixels differ from offscreen "
                      f"(at most {c['max_step']} steps)")
    print(f"{failures} failed" if failures else "every window draws on X11 what it draws offscreen")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
