"""Writes out/index.html from the steps' JSON reports (out/NN_name.json), their images, and
the tests' XML results (out/test_*.xml, doctest's XML reporter): every step's images,
its measurement tables and plots (matplotlib), and the status of every exercise.

usage: python3 -m tools.report OUT_DIR   (from the repository root; ./workbook tour runs it)
"""
import glob
import html
import json
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from .grading import ROOT  # noqa: E402
from .check import classify, parse_cases  # noqa: E402
from .grading.exercises import MAX_RESULT_BYTES, exercises as marked_exercises  # noqa: E402


def exercises():
    """(id, title, points, file) for every exercise marker in the steps' sources."""
    return [(e.id, e.title, e.points, e.path) for e in marked_exercises(ROOT)]


def suite_cases(out):
    """{suite name: its test cases} over the test_*.xml files in a folder (check's parse)."""
    by_suite = {}
    for path in sorted(glob.glob(os.path.join(out, "test_*.xml"))):
        try:
            with open(path, "rb") as f:
                data = f.read(MAX_RESULT_BYTES)
        except OSError:
            continue
        for c in parse_cases(data) or []:
            by_suite.setdefault(c["suite"], []).append(c)
    return by_suite


def checked_time(out):
    try:
        with open(os.path.join(out, "check", "status.json"), encoding="utf-8") as f:
            return json.load(f).get("time", "")
    except (OSError, ValueError, AttributeError):
        return ""


def check_status(out):
    """out/check/status.json (written by ./workbook check): {exercise: its entry}."""
    try:
        with open(os.path.join(out, "check", "status.json"), encoding="utf-8") as f:
            return {e["id"]: e for e in json.load(f).get("exercises", [])}
    except (OSError, ValueError, KeyError, TypeError):
        return {}


def table_html(t):
    rows = "".join(
        "<tr>" + "".join((f"<td class=num>{html.escape(fmt(c))}</td>" if isinstance(c, (int, float)) else f"<td>{html.escape(fmt(c))}</td>") for c in r) + "</tr>" for r in t["rows"]
    )
    head = "".join(f"<th>{html.escape(c)}</th>" for c in t["columns"])
    note = f"<p class=note>{html.escape(t['note'])}</p>" if t.get("note") else ""
    if t.get("time") and t.get("error"):
        tm = t["time"]
        note += (f"<p class=note>Time: <i>{html.escape(tm['median'])}</i> (spread "
                 f"<i>{html.escape(tm['low'])}</i> to <i>{html.escape(tm['high'])}</i>); error: "
                 f"<i>{html.escape(t['error'])}</i>, against the reference the note states.</p>")
    return f"<h3>{html.escape(t['title'])}</h3><table><tr>{head}</tr>{rows}</table>{note}"


def fmt(c):
    if isinstance(c, float):
        if c == 0:
            return "0"
        a = abs(c)
        if a >= 1e6 or a < 1e-3:
            return f"{c:.3g}"
        return f"{c:.1f}" if a >= 100 else f"{c:.4g}"
    return str(c)


def pareto_front(points):
    """The points no other point beats on both axes (smaller is better on each): the
    variants worth having. points: (x, y) pairs; returns them sorted by x."""
    front = []
    for p in sorted(set(points)):
        if not front or p[1] < front[-1][1]:
            front.append(p)
    return front


def plot(report, spec, out, name):
    table = next((t for t in report["tables"] if t["id"] == spec["table"]), None)
    if table is None:
        return None
    cols = table["columns"]
    try:
        xi, yi = cols.index(spec["x"]), cols.index(spec["y"])
    except ValueError:
        return None
    si = cols.index(spec["series"]) if spec.get("series") in cols else None
    # "point_label": a column written beside every point (a series' points then differ by
    # it, e.g. one point per mesh); without it a series of one point is labelled by name.
    li = cols.index(spec["point_label"]) if spec.get("point_label") in cols else None
    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=100)
    groups = {}
    for r in table["rows"]:
        x, y = r[xi], r[yi]
        if not isinstance(x, (int, float)) or not isinstance(y, (int, float)):
            continue
        key = str(r[si]) if si is not None else ""
        groups.setdefault(key, []).append((x, y, str(r[li]) if li is not None else ""))
    # Room around the points, so a label beside the highest or rightmost one is not cut off.
    ax.margins(x=0.08, y=0.1)
    # Long names (a whole sentence per variant) only in the legend, not beside their
    # points, where they ran over each other and out of the figure.
    names = [key for key in groups if key]
    short = len(names) <= 6 and all(len(key) <= 24 for key in names)
    for key, pts in groups.items():
        pts.sort()
        style = "o-" if spec.get("lines") else "o"
        ax.plot([p[0] for p in pts], [p[1] for p in pts], style, label=key or None)
        if li is not None:
            for p in pts:
                ax.annotate(p[2], p[:2], textcoords="offset points", xytext=(4, 3), fontsize=7,
                            color="#555")
        elif not spec.get("lines") and len(pts) == 1 and short:
            ax.annotate(key, pts[0][:2], textcoords="offset points", xytext=(5, 5), fontsize=8)

    def scale(axis, values, log):
        if not log:
            return
        set_scale = ax.set_xscale if axis == "x" else ax.set_yscale
        if all(v > 0 for v in values):
            set_scale("log")
            return
        # Zeros on a log axis: symlog, linear only below the smallest non-zero magnitude,
        # so the decades of the data keep their ticks (the default threshold, 1, made the
        # whole axis of errors below 1 linear, with a tick at each end only).
        magnitudes = [abs(v) for v in values if v != 0]
        set_scale("symlog", linthresh=min(magnitudes) if magnitudes else 1.0, linscale=0.5)

    points = [p for g in groups.values() for p in g]
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
        ax.plot(xs, ys, "-", color="#333", lw=1.2, alpha=0.6, zorder=0, label="Pareto front")
        on_front = set(front)
        dominated = [p for p in points if p[:2] not in on_front]
        if dominated:
            ax.plot([p[0] for p in dominated], [p[1] for p in dominated], "o", ms=11,
                    mfc="none", mec="#999", label="never worth it (another is better on both)")
    scale("x", [p[0] for p in points], spec.get("logx"))
    scale("y", [p[1] for p in points], spec.get("logy"))
    if points and not spec.get("logy") and all(p[1] == 0 for p in points):
        # Every variant exact: the points sit on the zero line at the bottom (the default
        # range, -0.06 to 0.06, showed errors below zero that no count can have).
        ax.set_ylim(-0.05, 1.0)
    ax.set_xlabel(spec["x"])
    ax.set_ylabel(spec["y"])
    ax.set_title(spec.get("title", table["title"]), fontsize=10, wrap=True)
    ax.grid(True, alpha=0.3)
    if (si is not None and len(groups) > 1) or spec.get("pareto"):  # below the axes
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(0.0, -0.16), frameon=False,
                  ncol=2 if short else 1)
    fig.tight_layout()
    path = os.path.join(out, name)
    fig.savefig(path, bbox_inches="tight")  # with a legend below the axes
    plt.close(fig)
    return os.path.basename(path)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "out"
    reports = []
    for path in sorted(glob.glob(os.path.join(out, "[0-9][0-9]_*.json"))):
        with open(path, encoding="utf-8") as f:
            reports.append(json.load(f))
    by_suite = suite_cases(out)
    checked = check_status(out)
    parts = []
    # Every step report names its machine; reports copied together from two machines say so.
    machines = sorted({r.get("machine", "an unknown machine") for r in reports})
    machine = " and ".join(machines) if machines else "an unknown machine"
    # Exercise status, in the words of ./workbook check (not started, needs N.M, ...).
    rows = []
    total = earned = 0
    for ex, title, points, src in exercises():
        cases = by_suite.get(f"exercise {ex}", [])
        entry = checked.get(ex)
        # The tour's own test run; for an exercise it did not run, check's last run.
        status = classify(ex, cases)[0] if cases else entry["status"] if entry else "not run"
        passed = sum(c["passed"] for c in cases)
        total += points
        earned += points if status == "passed" else 0
        css = {"passed": "passed", "failed": "failed", "not started": "notstarted"}.get(status, "other")
        picture = ""
        if entry and os.path.exists(os.path.join(out, "check", f"{ex}.png")):
            picture = (f"<a href='check/{ex}.png' title='{html.escape(entry.get('picture') or '')}'>"
                       f"picture</a> <span class=note>({html.escape(entry['status'])} at "
                       f"{html.escape(str(checked_time(out)))})</span>")
        elif entry and entry.get("picture"):
            picture = f"<span class=note>{html.escape(entry['picture'])}</span>"
        rows.append(
            f"<tr class={css}><td>{ex}</td><td>{html.escape(title)}</td>"
            f"<td>{points}</td><td>{f'{passed}/{len(cases)}' if cases else '-'}</td><td>{html.escape(status)}</td>"
            f"<td><code>{src}</code></td><td>{picture}</td></tr>"
        )
    parts.append(
        f"<h2 id=exercises>Exercises: {earned} of {total} points pass</h2>"
        "<p class=note>The same status as <code>./workbook check</code>; its pictures (yours, the "
        "reference, the pixels that differ) from its last run, out/check/.</p>"
        "<table><tr><th>exercise</th><th>what</th><th>points</th><th>test cases passed</th>"
        "<th>status</th><th>source</th><th>check's picture</th></tr>" + "".join(rows) + "</table>"
    )
    for r in reports:
        prog = r["program"]
        sec = [f"<h2 id='{prog}'>Step {html.escape(prog)}</h2>"]
        for img in r.get("images", []):
            rel = os.path.relpath(img["path"], out) if os.path.isabs(img["path"]) else os.path.relpath(img["path"], out)
            if rel.startswith(".."):
                rel = os.path.basename(img["path"])
            sec.append(
                f"<figure><img src='{html.escape(rel)}'><figcaption>{html.escape(img['caption'])}</figcaption></figure>"
            )
        for i, spec in enumerate(r.get("plots", [])):
            name = plot(r, spec, out, f"{prog}-plot{i}.png")
            if name:
                sec.append(f"<figure><img src='{name}'><figcaption>{html.escape(spec.get('title', ''))}</figcaption></figure>")
        for t in r.get("tables", []):
            sec.append(table_html(t))
        if r.get("facts"):
            facts = "".join(f"<li><b>{html.escape(k)}</b>: {html.escape(fmt(v))}</li>" for k, v in r["facts"].items())
            sec.append(f"<ul class=facts>{facts}</ul>")
        parts.append("<section>" + "".join(sec) + "</section>")
    slides = ""
    if os.path.exists(os.path.join(out, "slides", "index.html")):
        slides = "<p><a href='slides/index.html'>The slides</a></p>"
    nav = " | ".join(f"<a href='#{r['program']}'>{r['program']}</a>" for r in reports)
    page = f"""<!doctype html><html><head><meta charset=utf-8><title>Boxes workbook: the tour</title>
<style>body{{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}}
table{{border-collapse:collapse;margin:.5em 0;font-size:90%}}td,th{{border:1px solid #ccc;padding:2px 8px;text-align:left}}td.num{{text-align:right}}
tr.passed td{{background:#e8f6e8}}tr.failed td{{background:#fbe3e3}}tr.notstarted td{{color:#777}}
figure{{display:inline-block;margin:.5em}}img{{max-width:640px;border:1px solid #ddd}}.note{{color:#666;font-size:85%}}</style></head>
<body><h1>Boxes workbook: the tour</h1><p>Measured on {html.escape(machine)}. <a href='#exercises'>Exercises</a> | {nav}</p>{slides}
{''.join(parts)}</body></html>"""
    with open(os.path.join(out, "index.html"), "w", encoding="utf-8") as f:
        f.write(page)
    print(f"[workbook] wrote {os.path.join(out, 'index.html')}", file=sys.stderr)


if __name__ == "__main__":
    main()
