"""The pictures of `./workbook check`: for an exercise whose result shows in a step's image,
the step's program renders that image small and headless with the student's code, and
out/check/N.M.png puts it beside the reference image with the pixels that differ marked.

The reference images come with the starter kit (tests/reference/pictures/, with their
numbers in tests/reference/pictures.json): `./workbook kit` renders them from the
solutions (render_references below), so the kit holds the right answer's pictures, never
its code. In the full tree, which holds the solutions, its own render is the reference.
"""
import json
import os
import shutil
import subprocess
import tempfile

from . import label, png
from .grading.exercises import step_dirs

WIDTH, HEIGHT = 160, 120
# A pixel differs when a channel differs by more than this (of 255): correct solutions that
# round differently move a channel by a step or two; a wrong hit changes the colour.
TOLERANCE = 8
MARK = (255, 0, 255)  # differing pixels, over the reference dimmed
RING_RADIUS = 4  # pixels: the ring drawn around each differing pixel
REFERENCE_DIR = os.path.join("tests", "reference", "pictures")
REFERENCE_JSON = os.path.join("tests", "reference", "pictures.json")

# (key, step, the program's arguments, the exercises the image shows, what it shows, and
# the image's file: "" the program's --out, "-cull" the culling map it writes beside it)
PICTURES = [
    ("01-plane", 1, ["--test", "plane", "--flat"], ["1.1", "1.2", "1.3"],
     "the bunny through the plane test (exercises 1.1 to 1.3 together), flat shaded", ""),
    ("01-mt", 1, ["--test", "mt", "--flat"], ["1.4"], "the bunny through Moller-Trumbore, flat shaded", ""),
    ("01-watertight", 1, ["--test", "watertight", "--flat"], ["1.5"],
     "the bunny through the watertight test, flat shaded", ""),
    ("01-smooth", 1, ["--test", "mt"], ["1.6"], "the bunny through Moller-Trumbore, smooth shaded", ""),
    ("02-planes", 2, ["--method", "planes"], ["2.1", "2.2"], "the boxes as six planes each", ""),
    ("02-slabs", 2, ["--method", "slabs"], ["2.4"], "the boxes through the slab method", ""),
    ("03-pretest", 3, ["--pretest", "on", "--spheres", "300", "--triangles", "3000"],
     ["3.1", "3.2", "3.3", "3.4", "3.7"],
     "spheres, triangles and the bunny behind their boxes' conservative slab test", ""),
    ("04-midpoint", 4, ["--builder", "midpoint"], ["4.1", "4.4", "4.5"],
     "the bunny through the midpoint hierarchy (nearest-hit and shadow rays)", ""),
    ("04-median", 4, ["--builder", "median"], ["4.2"], "the bunny through the median hierarchy", ""),
    ("04-sah", 4, ["--builder", "sah"], ["4.3"], "the bunny through the binned SAH hierarchy", ""),
    ("04-culling", 4, ["--builder", "midpoint"], ["4.6", "4.7", "4.8"],
     "the culling map: the view frustum and the hierarchy's boxes it keeps, from above", "-cull"),
    ("06-raster", 6, ["--no-cull", "--shadows", "none"], ["6.1", "6.2", "6.3", "6.4", "6.5", "6.6", "6.7"],
     "the bunny rasterized, without shadows", ""),
    ("06-map", 6, ["--no-cull", "--shadows", "map"], ["6.8"], "the bunny rasterized with a shadow map", ""),
    ("06-rays", 6, ["--no-cull", "--shadows", "rays"], ["6.9"], "the bunny rasterized with shadow rays", ""),
]
# Why an exercise has no picture (the default: its result does not show in the step's image).
NOT_SHOWN = {
    "2.3": "the step's image goes through the slab or the six-plane method, not this helper",
    "3.5": "overlap tests decide nothing in the step's image",
    "3.6": "the step's image uses the conservative slab test (3.7)",
    "5.1": "the lab's tables measure it", "5.2": "the lab's tables measure it",
    "5.3": "the lab's tables measure it", "5.4": "the lab's tables measure it",
    "5.5": "the lab's tables measure it", "5.6": "the lab's tables measure it",
    "5.7": "the lab's tables measure it", "5.8": "the lab's tables measure it",
    "5.9": "the window shows it (line-by-line refinement), not the headless image",
    "5.10": "the window shows it (adaptive resolution), not the headless image",
}


def picture_of(exercise_id):
    return next((p for p in PICTURES if exercise_id in p[3]), None)


def program(root, build, step):
    for d in step_dirs(root):
        name = os.path.basename(d)
        if int(name[:2]) == step:
            return os.path.join(root, build, "steps", name, name), name
    return None, None


def render(binary, args, out, suffix="", timeout=120):
    """Renders one headless image into `out` (the program's own file, or the one it writes
    beside it with `suffix`); None, or why there is no image (one line)."""
    with tempfile.TemporaryDirectory(prefix="boxes-picture-") as tmp:
        image = os.path.join(tmp, "image.png")
        cmd = [binary, "--headless", "--width", str(WIDTH), "--height", str(HEIGHT), "--out", image] + args
        try:
            r = subprocess.run(cmd, cwd=tmp, capture_output=True, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return f"the program did not finish within {timeout} s"
        except OSError as exc:
            return f"the program did not start: {exc}"
        made = os.path.join(tmp, f"image{suffix}.png")
        if r.returncode == 0 and os.path.exists(made):
            shutil.copyfile(made, out)
            return None
    if r.returncode == 0:
        return f"the program wrote no image{suffix}.png"
    lines = [line for line in r.stderr.strip().splitlines() if line.strip()]
    last = lines[-1] if lines else f"exit code {r.returncode}"
    if r.returncode == 3:
        return f"the image waits for another exercise: {last}"
    if r.returncode < 0:
        return f"the program crashed rendering it (signal {-r.returncode})"
    return f"the program failed: {last}"


def compare(mine, reference, out):
    """Writes [mine | reference | differences] to out, each panel named above it, and
    returns the differing pixel count. A differing pixel is magenta with a magenta ring
    around it (a single pixel is easy to miss) on the reference dimmed to grey."""
    w, h, a = png.read(mine)
    rw, rh, b = png.read(reference)
    if (w, h) != (rw, rh):
        raise png.PngError(f"the images differ in size ({w}x{h} and {rw}x{rh})")
    differs = []
    diff = []
    for y in range(h):
        ra, rb = a[y], b[y]
        row = bytearray(3 * w)
        for x in range(w):
            i = 3 * x
            if max(abs(ra[i] - rb[i]), abs(ra[i + 1] - rb[i + 1]), abs(ra[i + 2] - rb[i + 2])) > TOLERANCE:
                differs.append((x, y))
            grey = (int(rb[i]) + rb[i + 1] + rb[i + 2]) // 9  # the reference, dimmed
            row[i : i + 3] = bytes((grey, grey, grey))
        diff.append(row)
    ring = RING_RADIUS
    for x, y in differs:
        for dy in range(-ring - 1, ring + 2):
            for dx in range(-ring - 1, ring + 2):
                d2 = dx * dx + dy * dy
                on_ring = ring * ring - ring <= d2 <= ring * ring + ring
                px, py = x + dx, y + dy
                if (on_ring or d2 == 0) and 0 <= px < w and 0 <= py < h:
                    diff[py][3 * px : 3 * px + 3] = bytes(MARK)
    count = len(differs)
    gap, strip, scale = 4, 2 * label.GLYPH_H + 8, 2
    names = ["yours", "reference", f"{count} differ" if count else "none differ"]
    white = b"\xff" * (3 * gap)
    rows = [bytearray(b"\xff" * 3 * (3 * w + 2 * gap)) for _ in range(strip)]
    for k, name in enumerate(names):
        left = k * (w + gap) + max(0, (w - label.text_width(name, scale)) // 2)
        colour = MARK if k == 2 and count else (40, 40, 40)
        label.draw(rows, left, 4, name, colour, scale)
    for y in range(h):
        rows.append(bytearray(a[y]) + white + bytearray(b[y]) + white + diff[y])
    png.write(out, 3 * w + 2 * gap, h + strip, rows)
    return count


def references(root):
    try:
        with open(os.path.join(root, REFERENCE_JSON), encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def is_reference_tree(root):
    return os.path.exists(os.path.join(root, "tools", "grading", "grade.py"))


def make(root, rows, first, out_dir, say, build=os.path.join("build", "release")):
    """Renders the pictures of the rows that were attempted (passed or failed) and of the
    first row not passing; returns {exercise: the line to show}."""
    shown, done = {}, {}
    wanted = [r for r in rows if r["status"] in ("passed", "failed") or r is first]
    if not wanted:
        return shown
    os.makedirs(out_dir, exist_ok=True)
    work = os.path.join(root, "build", "check-pictures")
    os.makedirs(work, exist_ok=True)
    refs = references(root)
    for r in wanted:
        pic = picture_of(r["id"])
        if pic is None:
            why = NOT_SHOWN.get(r["id"], "its result does not show in the step's image")
            shown[r["id"]] = f"none: exercise {r['id']} is not visible in an image ({why}); its tests are the check"
            continue
        if r["status"] in ("not started", "does not compile") or r["status"].startswith("needs"):
            shown[r["id"]] = f"{pic[4]}: once the exercise runs"
            continue
        key, step, args, _, what, _ = pic
        if key not in done:
            done[key] = picture(root, build, work, out_dir, pic, refs, say)
        line, path = done[key]
        if path:
            dest = os.path.join(out_dir, f"{r['id']}.png")
            shutil.copyfile(path, dest)
            line = f"{os.path.relpath(dest, root)} ({what}; yours, the reference, differences ringed in magenta): {line}"
        shown[r["id"]] = line
    return shown


def picture(root, build, work, out_dir, pic, refs, say):
    """(the line to show, the composite's path or None) for one picture."""
    key, step, args, _, _, suffix = pic
    binary, name = program(root, build, step)
    if not binary or not os.path.exists(binary):
        return f"step {step:02d}'s program is not built", None
    mine = os.path.join(work, f"{key}.png")
    say(f"[check] rendering {key} ({name} {' '.join(args)}, {WIDTH}x{HEIGHT})")
    problem = render(binary, args, mine, suffix)
    if problem:
        return problem, None
    ref = os.path.join(root, REFERENCE_DIR, f"{key}.png")
    note = ""
    if not os.path.exists(ref):
        if not is_reference_tree(root):
            return "no reference picture in this tree (./workbook kit renders them into the kit)", None
        ref, note = mine, " (this tree holds the solutions: its render is the reference)"
    composite = os.path.join(work, f"{key}-compare.png")
    try:
        count = compare(mine, ref, composite)
    except (OSError, png.PngError) as exc:
        return f"cannot compare: {exc}", None
    total = WIDTH * HEIGHT
    if count == 0:
        return f"identical to the reference{note}", composite
    return f"{count} of {total} pixels differ from the reference", composite


def render_references(dest, root, steps=None, build=os.path.join("build", "release"), log=print,
                      build_programs=True):
    """Renders every picture (of the steps given, default all) with the tree `root`'s
    programs (the solutions) into the kit `dest`, with their numbers. Builds the programs
    first (build_programs), so they are the solutions as they are now."""
    chosen = [p for p in PICTURES if steps is None or p[1] in steps]
    names = sorted({program(root, build, p[1])[1] for p in chosen if program(root, build, p[1])[1]})
    if build_programs:
        if not os.path.exists(os.path.join(root, build, "build.ninja")):
            subprocess.run(["cmake", "--preset", "release"], cwd=root, check=True, capture_output=True)
        log(f"[workbook] building the reference programs for the kit's pictures: {' '.join(names)}")
        r = subprocess.run(["cmake", "--build", build, "--target"] + names, cwd=root,
                           capture_output=True, text=True)
        if r.returncode != 0:
            raise SystemExit("kit: the reference programs do not build:\n" + r.stdout[-2000:]
                             + r.stderr[-2000:])
    os.makedirs(os.path.join(dest, REFERENCE_DIR), exist_ok=True)
    numbers = {}
    for key, step, args, shows, what, suffix in chosen:
        binary, name = program(root, build, step)
        out = os.path.join(dest, REFERENCE_DIR, f"{key}.png")
        problem = render(binary, args, out, suffix) if binary and os.path.exists(binary) else "not built"
        if problem:
            # The kit goes on without it: check then says it has no reference picture.
            log(f"  {key}: NO reference picture ({name} {' '.join(args)}): {problem}")
            continue
        w, h, rows = png.read(out)
        n = w * h
        mean = [round(sum(sum(row[c::3]) for row in rows) / n, 2) for c in range(3)]
        numbers[key] = {"program": name, "arguments": args, "width": w, "height": h,
                        "exercises": shows, "shows": what, "mean_rgb": mean}
        log(f"  {key}: {what} ({w}x{h})")
    with open(os.path.join(dest, REFERENCE_JSON), "w", encoding="utf-8") as f:
        json.dump({"note": "rendered from the reference solutions by ./workbook kit; "
                           "pictures and numbers only", "pictures": numbers}, f, indent=1)
    return numbers
