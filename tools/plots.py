"""The steps' plots, drawn once for the report page and the decks: each plot a report asks
for ({"table", "x", "y", "series", "point_label", "pareto", "lines", "logx", "logy",
"title"}) as an SVG that reads in a room. Every point carries its name where one
point stands for one variant, placed where it overlaps no other name or point (with a
thin line back to its point when it had to move away); colours from the Okabe-Ito
palette, which colour-blind readers tell apart, each series with its own marker too; a
plot of error against time whose errors are all zero becomes a bar chart of the times.

usage: python3 -m tools.plots OUT_DIR   (writes OUT_DIR/plots/NN_name-N.svg for every
                                          OUT_DIR/NN_name.json; the tour runs it)
"""
import glob
import json
import os
import sys
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# Okabe and Ito (2008), "Color universal design": distinct for the common colour blindnesses.
# Its yellow is left out: too faint for a name written in it.
COLOURS = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#882255"]
MARKERS = ["o", "s", "^", "D", "v", "P", "X", "*"]
SIZE = (6.4, 3.6)  # inches: 16:9, the decks' shape; small, so the letters are large beside it
matplotlib.rcParams["font.size"] = 10
matplotlib.rcParams["svg.fonttype"] = "path"  # the same letters in every browser, offline
matplotlib.rcParams["svg.hashsalt"] = "boxes"  # the same file for the same plot


def pareto_front(points):
    """The points no other point beats on both axes (smaller is better on each): the
    variants worth having. points: (x, y) pairs; returns them sorted by x."""
    front = []
    for p in sorted(set(points)):
        if not front or p[1] < front[-1][1]:
            front.append(p)
    return front


def fit_title(title, width=70):
    """The title in lines no wider than the axes, so no plot is drawn smaller on the page
    for the sake of its title."""
    return "\n".join(textwrap.fill(line, width) for line in title.split("\n"))


def _number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def gather(table, spec):
    """{series name: [(x, y, label, row)]} of the table's numeric points, or None."""
    cols = table["columns"]
    if spec["x"] not in cols or spec["y"] not in cols:
        return None
    xi, yi = cols.index(spec["x"]), cols.index(spec["y"])
    si = cols.index(spec["series"]) if spec.get("series") in cols else None
    li = cols.index(spec["point_label"]) if spec.get("point_label") in cols else None
    # Without a label column, the first column names a point when it is not the series
    # (op_cost: the operation beside its type; language: the flags beside float/double).
    if li is None and si != 0 and 0 not in (xi, yi) and (si is not None or spec.get("lines")):
        li = 0
    if spec.get("lines") and si is not None and li == 0:
        li = None  # several lines: the legend names them, names at every point would crowd
    groups = {}
    for r in table["rows"]:
        if not _number(r[xi]) or not _number(r[yi]):
            continue
        key = str(r[si]) if si is not None else ""
        name = "" if li is None else f"{r[li]:g} {cols[li]}" if _number(r[li]) else str(r[li])
        groups.setdefault(key, []).append((float(r[xi]), float(r[yi]), name, r))
    # A series of one point is named by the series (the legend's colour then says nothing
    # more); the points of a longer series without a label column by the legend alone.
    for key, pts in groups.items():
        if li is None and len(pts) == 1:
            pts[0] = pts[0][:2] + (key,) + pts[0][3:]
    return groups


def _scale(ax, axis, values, log):
    if not log:
        return
    set_scale = ax.set_xscale if axis == "x" else ax.set_yscale
    if all(v > 0 for v in values):
        set_scale("log")
        return
    # Zeros on a log axis: symlog, linear only below the smallest non-zero magnitude, so
    # the decades of the data keep their ticks.
    magnitudes = [abs(v) for v in values if v != 0]
    threshold = min(magnitudes) if magnitudes else 1.0
    set_scale("symlog", linthresh=threshold, linscale=0.5)
    if all(v >= 0 for v in values):  # no negative decade below the zeros
        (ax.set_xlim if axis == "x" else ax.set_ylim)(-0.3 * threshold, None)


def _overlaps(a, b, pad=2.0):
    return not (a.x1 + pad < b.x0 or b.x1 + pad < a.x0 or a.y1 + pad < b.y0 or b.y1 + pad < a.y0)


def place_labels(fig, ax, points, fontsize=10, lines=(), marker=8):
    """Names beside their points, none over another name or point and all inside the axes:
    for each point the first free spot of a ring of candidates around it, nearest first
    (right, above, left, below, then the diagonals, then further out), with a line back to
    the point beyond the first ring. Points at the same spot share one name ("a = b").
    points: [(x, y, label, colour)]; lines: polylines [(xs, ys)] in data units that names
    must not cover either; marker: pixels around a point a name leaves free. Returns the
    text artists."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    to_px = ax.transData.transform
    frame = ax.get_window_extent(renderer)
    # Points drawn on the same spot (within 3 pixels) get one name.
    spots = []
    for x, y, label, colour in points:
        px = to_px((x, y))
        for s in spots:
            if abs(s["px"][0] - px[0]) <= 3 and abs(s["px"][1] - px[1]) <= 3:
                if label not in s["labels"]:
                    s["labels"].append(label)
                break
        else:
            spots.append({"px": px, "xy": (x, y), "labels": [label], "colour": colour})
    near = marker + 3  # a name this close to its point needs no line
    taken = [matplotlib.transforms.Bbox.from_extents(s["px"][0] - marker, s["px"][1] - marker,
                                                     s["px"][0] + marker, s["px"][1] + marker)
             for s in spots]
    for xs, ys in lines:  # each segment as small boxes every few pixels
        pts = [to_px(p) for p in zip(xs, ys)]
        for (x0, y0), (x1, y1) in zip(pts, pts[1:]):
            n = max(1, int(max(abs(x1 - x0), abs(y1 - y0)) / 4))
            for k in range(n + 1):
                x, y = x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n
                taken.append(matplotlib.transforms.Bbox.from_extents(x - 1, y - 1, x + 1, y + 1))
    directions = [(1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, 1), (-1, -1), (1, -1)]
    texts = []
    # The crowded points first: they have the fewest free spots.
    def crowding(s):
        return -sum(1 for o in spots if abs(o["px"][0] - s["px"][0]) < 80 and abs(o["px"][1] - s["px"][1]) < 30)
    for s in sorted(spots, key=crowding):
        label = " = ".join(s["labels"])
        text = ax.annotate(label, s["xy"], textcoords="offset points", xytext=(0, 0), fontsize=fontsize,
                           color=s["colour"], ha="left", va="bottom", zorder=5)
        size = text.get_window_extent(renderer)
        w, h = size.width, size.height
        choice = None
        for distance in (near, 24, 40, 60, 84, 112):
            for dx, dy in directions:
                # The name's corner nearest the point, `distance` pixels away along (dx, dy).
                cx = s["px"][0] + dx * distance + (0 if dx > 0 else -w if dx < 0 else -w / 2)
                cy = s["px"][1] + dy * distance + (0 if dy > 0 else -h if dy < 0 else -h / 2)
                box = matplotlib.transforms.Bbox.from_extents(cx, cy, cx + w, cy + h)
                inside = (box.x0 >= frame.x0 + 2 and box.x1 <= frame.x1 - 2 and box.y0 >= frame.y0 + 2
                          and box.y1 <= frame.y1 - 2)
                if inside and not any(_overlaps(box, t) for t in taken):
                    choice = (cx, cy, box, distance if (dx, dy) == (1, 0) else distance + 1)
                    break
            if choice:
                break
        if choice is None:  # nowhere free: right of the point, over what is there
            cx, cy = s["px"][0] + near, s["px"][1] + 4
            choice = (cx, cy, matplotlib.transforms.Bbox.from_extents(cx, cy, cx + w, cy + h), near)
        cx, cy, box, distance = choice
        taken.append(box)
        # Offsets in points (pixels at this dpi), which keep their place in any file format.
        pt = 72.0 / fig.dpi
        text.xyann = ((cx - s["px"][0]) * pt, (cy - s["px"][1]) * pt)
        if distance > near:
            # A thin line from the point to the nearest spot of its name's box.
            ex = min(max(s["px"][0], box.x0), box.x1) - s["px"][0]
            ey = min(max(s["px"][1], box.y0), box.y1) - s["px"][1]
            ax.annotate("", s["xy"], xytext=(ex * pt, ey * pt), textcoords="offset points", zorder=4,
                        arrowprops={"arrowstyle": "-", "color": "#999", "lw": 0.7, "shrinkA": 1, "shrinkB": 6})
        texts.append(text)
    return texts


def _bars(table, spec, groups, title):
    """Every error zero: the variants' times as bars, with their spread where the table
    has one; an error axis of zeros says nothing."""
    rows = [p for pts in groups.values() for p in pts]
    rows.sort(key=lambda p: p[0])
    cols = table["columns"]
    time = table.get("time") or {}
    lo = cols.index(time["low"]) if time.get("low") in cols and time.get("median") == spec["x"] else None
    hi = cols.index(time["high"]) if time.get("high") in cols and time.get("median") == spec["x"] else None
    fig, ax = plt.subplots(figsize=SIZE, dpi=100)  # the same size as every plot
    names = [p[2] or spec["x"] for p in rows]
    values = [p[0] for p in rows]
    errors = None
    if lo is not None and hi is not None and all(_number(p[3][lo]) and _number(p[3][hi]) for p in rows):
        errors = [[p[0] - p[3][lo] for p in rows], [p[3][hi] - p[0] for p in rows]]
    keys = list(groups)
    colours = [COLOURS[keys.index(next(k for k, g in groups.items() if p in g)) % len(COLOURS)] for p in rows]
    ax.barh(range(len(rows)), values, xerr=errors, color=colours, alpha=0.85, capsize=3,
            error_kw={"lw": 1, "ecolor": "#444"})
    ax.set_yticks(range(len(rows)), names, fontsize=10)
    ax.invert_yaxis()
    for i, v in enumerate(values):  # the median's value right of its bar and whisker
        end = v + (errors[1][i] if errors else 0.0)
        ax.annotate(f"{v:.3g}", (end, i), textcoords="offset points", xytext=(5, 0), fontsize=9,
                    color="#333", va="center")
    ax.set_xlabel(spec["x"] + (" (bars: median; whiskers: min to max)" if errors else ""))
    ax.set_title(fit_title(f"{title}\nevery variant exact ({spec['y']} = 0): only the time tells them apart"),
                 fontsize=10.5)
    ax.margins(x=0.15)
    ax.grid(True, axis="x", alpha=0.3)
    return fig


def draw(report, spec):
    """The plot as a matplotlib figure, or None when its table or columns are missing."""
    table = next((t for t in report.get("tables", []) if t["id"] == spec.get("table")), None)
    if table is None:
        return None
    groups = gather(table, spec)
    if not groups:
        return None
    title = spec.get("title", table["title"])
    points = [p for g in groups.values() for p in g]
    if spec.get("pareto") and all(p[1] == 0 for p in points):
        return _bars(table, spec, groups, title)
    fig, ax = plt.subplots(figsize=SIZE, dpi=100)
    keys = list(groups)
    # One name per point where a point is a variant (not along a line of many points).
    named = any(p[2] for p in points)
    one_per_series = all(len(g) == 1 for g in groups.values())
    for k, (key, pts) in enumerate(groups.items()):
        pts.sort()
        ax.plot([p[0] for p in pts], [p[1] for p in pts], ("-" if spec.get("lines") else "") + MARKERS[k % len(MARKERS)],
                color=COLOURS[k % len(COLOURS)], ms=7, label=key or None, zorder=3)
    _scale(ax, "x", [p[0] for p in points], spec.get("logx"))
    _scale(ax, "y", [p[1] for p in points], spec.get("logy"))
    ax.margins(x=0.12, y=0.15)
    if not spec.get("logy") and all(p[1] == 0 for p in points):
        ax.set_ylim(-0.05, 1.0)  # every error zero: the points on the zero line, no negative range
    avoid = [([p[0] for p in g], [p[1] for p in g]) for g in groups.values()] if spec.get("lines") else []
    if spec.get("pareto"):
        # The front as a staircase: right of a point and above it nothing is better.
        front = pareto_front([p[:2] for p in points])
        xs, ys = [], []
        for i, (fx, fy) in enumerate(front):
            if i:
                xs.append(fx)
                ys.append(front[i - 1][1])
            xs.append(fx)
            ys.append(fy)
        ax.plot(xs, ys, "-", color="#333", lw=1.2, alpha=0.6, zorder=1)
        avoid.append((xs, ys))
        on_front = set(front)
        dominated = [p for p in points if p[:2] not in on_front]
        if dominated:
            ax.plot([p[0] for p in dominated], [p[1] for p in dominated], "o", ms=14, mfc="none",
                    mec="#999", zorder=2)
    ax.set_xlabel(spec["x"])
    ax.set_ylabel(spec["y"])
    if spec.get("pareto"):  # what the line and the rings mean, where a reader looks first
        title += "\nline: the Pareto front; ringed: another point is better on both axes"
    ax.set_title(fit_title(title), fontsize=10.5)
    ax.grid(True, alpha=0.3)
    if named:
        place_labels(fig, ax, [(p[0], p[1], p[2], COLOURS[k % len(COLOURS)])
                               for k, g in enumerate(groups.values()) for p in g if p[2]],
                     lines=avoid, marker=11 if spec.get("pareto") else 8)
    # A legend only where colours mean something the names beside the points do not say:
    # the series of a line plot or of several points each.
    # Below the figure, under the x axis's label (never over it), so every plot keeps the
    # same width and the same size of letters on the page.
    if any(keys) and (not named or not one_per_series):
        fig.tight_layout()
        fig.legend(*ax.get_legend_handles_labels(), fontsize=9, loc="upper center",
                   bbox_to_anchor=(0.5, 0.0), frameon=False,
                   ncol=min(len(keys), 2 if max(len(k) for k in keys) > 12 else 4))
    return fig


def plot(report, spec, out, name):
    """Draws the plot into out/name (.svg or .png); its file name, or None."""
    fig = draw(report, spec)
    if fig is None:
        return None
    path = os.path.join(out, name)
    fig.savefig(path, bbox_inches="tight", metadata={"Date": None} if name.endswith(".svg") else None)
    plt.close(fig)
    return os.path.basename(path)


def plot_path(out, program, index):
    return os.path.join(out, "plots", f"{program}-{index}.svg")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "out"
    os.makedirs(os.path.join(out, "plots"), exist_ok=True)
    count = 0
    for path in sorted(glob.glob(os.path.join(out, "[0-9][0-9]_*.json"))):
        with open(path, encoding="utf-8") as f:
            report = json.load(f)
        for i, spec in enumerate(report.get("plots", [])):
            target = plot_path(out, report["program"], i)
            if plot(report, spec, os.path.dirname(target), os.path.basename(target)):
                count += 1
    print(f"[workbook] drew {count} plots into {os.path.join(out, 'plots')}", file=sys.stderr)


if __name__ == "__main__":
    main()
