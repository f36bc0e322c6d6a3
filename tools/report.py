"""Writes out/index.html, the tour's report page, from the steps' JSON reports
(out/NN_name.json), their images, the plots (tools/plots.py), the check of what the READMEs
state against this run (out/claims.json, slides/claims.mjs --json) and the tests' XML
results (out/test_*.xml, doctest's XML reporter).

Each step's section is a guide: what the step measured and what to conclude (the README's
summary, with this run's numbers), the README's "What to look for" with each point marked
as agreeing with this run or not, links to the README, the deck and docs/measuring.md, then
the images side by side, the plots and tables each with its takeaway (long tables folded),
and the facts as labelled values with units. The page needs no network.

usage: python3 -m tools.report OUT_DIR   (from the repository root; ./workbook tour runs it)
"""
import glob
import html
import json
import os
import re
import sys

from .grading import ROOT
from .check import classify, parse_cases
from .grading.exercises import MAX_RESULT_BYTES, exercises as marked_exercises

FOLD_ROWS = 6  # a table of more rows opens on a click
MARKS = {  # a "What to look for" point against this run
    "agree": ("&#10004;", "agrees with this run"),
    "disagree": ("&#10008;", "disagrees with this run"),
    "error": ("&#10008;", "its check cannot be read"),
    "not measured": ("&#8211;", "not measured in this run"),
    "unchecked": ("&#9675;", "not checked against the numbers"),
}


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


def _json(path, default):
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError):
        return default


def checked_time(out):
    status = _json(os.path.join(out, "check", "status.json"), {})
    return status.get("time", "") if isinstance(status, dict) else ""


def check_status(out):
    """out/check/status.json (written by ./workbook check): {exercise: its entry}."""
    status = _json(os.path.join(out, "check", "status.json"), {})
    try:
        return {e["id"]: e for e in status.get("exercises", [])}
    except (AttributeError, KeyError, TypeError):
        return {}


def fmt(c):
    if isinstance(c, bool):
        return "yes" if c else "no"
    if isinstance(c, int):
        return f"{c:,}"
    if isinstance(c, float):
        if c == 0:
            return "0"
        a = abs(c)
        if a >= 1e6 or a < 1e-3:
            return f"{c:.3g}"
        return f"{c:.1f}" if a >= 100 else f"{c:.4g}"
    return str(c)


def inline(text, base):
    """The README's inline Markdown as HTML: `code`, **bold**, *emphasis*, [links](...) with
    relative targets taken from `base` (the README's folder, from the page's)."""
    out, pos = [], 0
    for m in re.finditer(r"`([^`]+)`|\*\*(.+?)\*\*|\*(.+?)\*|\[([^\]]+)\]\(([^)\s]+)\)", text):
        out.append(html.escape(text[pos:m.start()]))
        if m.group(1) is not None:
            out.append(f"<code>{html.escape(m.group(1))}</code>")
        elif m.group(2) is not None:
            out.append(f"<b>{html.escape(m.group(2))}</b>")
        elif m.group(3) is not None:
            out.append(f"<i>{html.escape(m.group(3))}</i>")
        else:
            target = m.group(5)
            if not re.match(r"^[a-z]+:|^#", target):
                target = os.path.normpath(os.path.join(base, target.split("#")[0])) + (
                    "#" + target.split("#", 1)[1] if "#" in target else "")
            out.append(f"<a href='{html.escape(target)}'>{html.escape(m.group(4))}</a>")
        pos = m.end()
    out.append(html.escape(text[pos:]))
    return "".join(out)


def anchor(heading):
    """GitHub's anchor of a Markdown heading: "Step 01: triangles" -> "step-01-triangles"."""
    return re.sub(r"[^a-z0-9 _-]", "", heading.strip().lower()).replace(" ", "-")


def measuring_anchor(program):
    """docs/measuring.md's section of a step ("## Step 01: ..."), or ""."""
    try:
        with open(os.path.join(ROOT, "docs", "measuring.md"), encoding="utf-8") as f:
            for line in f:
                if line.startswith(f"## Step {program[:2]}"):
                    return "#" + anchor(line[3:])
    except OSError:
        pass
    return ""


# Facts: a label and a unit from the key's own words (render_ms: "render: 890.4 ms"), so a
# new fact reads right without an entry here; these read better in words of their own.
FACT_LABELS = {
    "rays": "rays traced for the image",
    "render_ms": ("the image's render time", "ms"),
    "pixels_disagreeing": "pixels where the methods disagree",
    "pretest_pixels_differing": "pixels that differ with and without the pre-test",
    "nodes": "nodes in the image's tree",
    "sah_cost": "SAH cost of the image's tree",
    "build_ms": ("one build of the image's tree", "ms"),
    "refined_image_bit_identical": "refined image bit-identical to the full render",
    "refinement_frames": "frames the refinement took",
    "refinement_budget_ms": ("time budget per refinement frame", "ms"),
    "total_speedup": ("all optimizations together, against the naive render", "x faster"),
    "slab_speedup_float": ("slabs against six planes, float", "x faster"),
}
UNITS = [("_ns_per_test", "ns per test"), ("_ms", "ms"), ("_ns", "ns"), ("_pct", "%"),
         ("_speedup", "x faster"), ("_ratio", "x")]


def fact_label(key):
    """(label, unit) of a fact's key."""
    known = FACT_LABELS.get(key)
    if isinstance(known, tuple):
        return known
    if known:
        return known, ""
    for suffix, unit in UNITS:
        if key.endswith(suffix):
            return key[: -len(suffix)].replace("_", " "), unit
    return key.replace("_", " "), ""


def facts_html(facts):
    items = []
    for key, value in facts.items():
        label, unit = fact_label(key)
        shown = fmt(value) + (f" {unit}" if unit and not isinstance(value, bool) else "")
        items.append(f"<dt>{html.escape(label[:1].upper() + label[1:])}</dt><dd>{html.escape(shown)}</dd>")
    return f"<dl class=facts>{''.join(items)}</dl>"


def takeaway_html(text):
    if not text:
        return ""
    return f"<p class=takeaway><span class=label>Takeaway</span> {text}</p>"


def table_html(t, takeaway="", base="."):
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
    body = f"<table><tr>{head}</tr>{rows}</table>{note}"
    title = f"{html.escape(t['title'])} <span class=id>({html.escape(t['id'])}, {len(t['rows'])} rows)</span>"
    take = takeaway_html(inline(takeaway, base) if takeaway else "")
    opened = " open" if len(t["rows"]) <= FOLD_ROWS else ""
    return (f"<div class=table data-table='{html.escape(t['id'])}'>"
            f"<details{opened}><summary>{title}</summary>{body}</details>{take}</div>")


def plot_html(out, report, i, spec, takeaway, base):
    from . import plots  # matplotlib: only where the page has plots

    path = plots.plot_path(out, report["program"], i)
    if not os.path.exists(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        if not plots.plot(report, spec, os.path.dirname(path), os.path.basename(path)):
            return ""
    rel = os.path.relpath(path, out)
    title = spec.get("title", "")
    # The title is in the figure; under it, what to take from it.
    return (f"<figure class=plot data-plot='{i}'><img src='{html.escape(rel)}' alt='{html.escape(title)}'>"
            f"<figcaption>{takeaway_html(inline(takeaway, base) if takeaway else '')}</figcaption></figure>")


def image_rel(img, out):
    rel = os.path.relpath(img["path"], out) if os.path.isabs(img["path"]) else os.path.relpath(img["path"], out)
    if rel.startswith("..") or not os.path.exists(os.path.join(out, rel)):
        rel = os.path.basename(img["path"])
    return rel


def mark_html(bullet, base):
    symbol, words = MARKS.get(bullet["status"], MARKS["unchecked"])
    how = "; ".join(f"{c['expression']}: {c['shown']}" for c in bullet.get("checks", []))
    title = f"{words}" + (f" ({how})" if how else "")
    return (f"<li class='point {html.escape(bullet['status'].replace(' ', '-'))}'>"
            f"<span class=mark title='{html.escape(title)}'>{symbol} <span class=words>{html.escape(words)}</span></span> "
            f"<span class=text>{inline(bullet['text'], base)}</span></li>")


def step_html(out, r, guide, decks):
    prog = r["program"]
    readme = os.path.join(ROOT, "steps", prog, "README.md")
    base = os.path.relpath(os.path.dirname(readme), out)
    title = prog
    try:
        with open(readme, encoding="utf-8") as f:
            first = f.readline()
        if first.startswith("# "):
            title = first[2:].strip()
    except OSError:
        pass
    sec = [f"<h2 id='{html.escape(prog)}'>{html.escape(title)}</h2>"]
    summary = guide.get("summary")
    if summary:
        sec.append(f"<p class=summary>{inline(summary, base)}</p>")
    else:
        sec.append("<p class='summary missing'>No summary of this run: its README states none, or "
                   "the check of the READMEs against this run (slides/claims.mjs, Node.js) did not run.</p>")
    deck = f"slides/{prog}.html" if prog in decks else os.path.relpath(os.path.join(ROOT, "slides", f"{prog}.md"), out)
    measuring = os.path.relpath(os.path.join(ROOT, "docs", "measuring.md"), out) + measuring_anchor(prog)
    sec.append(
        "<p class=links>"
        f"<a class=readme href='{html.escape(os.path.relpath(readme, out))}'>the step's README</a> · "
        f"<a class=deck href='{html.escape(deck)}'>its slides</a> · "
        f"<a class=measuring href='{html.escape(measuring)}'>how its tables are measured (docs/measuring.md)</a></p>")
    bullets = guide.get("bullets") or []
    if bullets:
        sec.append("<h3>What to look for</h3><ul class=points>" + "".join(mark_html(b, base) for b in bullets) + "</ul>")
    takeaways = guide.get("takeaways") or {}
    images = r.get("images", [])
    if images:
        sec.append("<div class=gallery>" + "".join(
            f"<figure><a href='{html.escape(image_rel(img, out))}'><img src='{html.escape(image_rel(img, out))}' "
            f"alt='{html.escape(img['caption'])}'></a><figcaption>{html.escape(img['caption'])}</figcaption></figure>"
            for img in images) + "</div>")
    plots_html = [plot_html(out, r, i, spec, takeaways.get(f"plot {i}", ""), base) for i, spec in enumerate(r.get("plots", []))]
    if any(plots_html):
        sec.append("<div class=plots>" + "".join(plots_html) + "</div>")
    for t in r.get("tables", []):
        sec.append(table_html(t, takeaways.get(t["id"], ""), base))
    if r.get("facts"):
        sec.append("<h3>Facts of this run</h3>" + facts_html(r["facts"]))
    return "<section class=step>" + "".join(sec) + "</section>"


def exercises_html(out):
    by_suite = suite_cases(out)
    checked = check_status(out)
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
    return (
        f"<section id=exercises><h2>Exercises: {earned} of {total} points pass</h2>"
        "<details><summary>Every exercise, its tests and its status (the same as <code>./workbook "
        "check</code>; its pictures, yours beside the reference, from its last run)</summary>"
        "<table><tr><th>exercise</th><th>what</th><th>points</th><th>test cases passed</th>"
        "<th>status</th><th>source</th><th>check's picture</th></tr>" + "".join(rows) + "</table></details></section>"
    )


STYLE = """body{font-family:sans-serif;max-width:1180px;margin:1.5em auto;padding:0 1em;color:#222;line-height:1.4}
h2{border-top:3px solid #0072B2;padding-top:.6em;margin-top:2em}
table{border-collapse:collapse;margin:.5em 0;font-size:88%}td,th{border:1px solid #ccc;padding:2px 8px;text-align:left}td.num{text-align:right}
tr.passed td{background:#e8f6e8}tr.failed td{background:#fbe3e3}tr.notstarted td{color:#777}
.summary{font-size:110%;background:#f3f7fb;border-left:4px solid #0072B2;padding:.6em .9em}
.links a{margin-right:.3em}
ul.points{list-style:none;padding-left:0}ul.points li{margin:.45em 0;display:flex;gap:.8em}
.mark{flex:0 0 9.5em;font-size:85%;font-weight:bold;padding-top:.1em}.text{flex:1}
.agree .mark{color:#1a7f37}.disagree .mark,.error .mark{color:#cf222e}.unchecked .mark,.not-measured .mark{color:#777}
.gallery,.plots{display:flex;flex-wrap:wrap;gap:12px;align-items:flex-start}
.gallery figure{margin:0;flex:1 1 300px;max-width:420px}.gallery img{width:100%;border:1px solid #ddd}
.plots figure{margin:0;flex:1 1 520px;max-width:580px}.plots img{width:100%}
figcaption{font-size:88%;color:#444}
.takeaway{margin:.3em 0;font-size:95%}.takeaway .label{background:#0072B2;color:#fff;border-radius:3px;padding:0 5px;font-size:80%;margin-right:.3em}
div.table{margin:1em 0}summary{cursor:pointer;font-weight:bold}summary .id{font-weight:normal;color:#777;font-size:85%}
.note{color:#666;font-size:85%}
dl.facts{display:grid;grid-template-columns:max-content auto;gap:2px 16px;font-size:92%}dl.facts dt{color:#555}dl.facts dd{margin:0;font-weight:bold}
nav a{margin-right:.6em}"""


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "out"
    reports = []
    for path in sorted(glob.glob(os.path.join(out, "[0-9][0-9]_*.json"))):
        with open(path, encoding="utf-8") as f:
            report = json.load(f)
        if "program" in report and os.path.isdir(os.path.join(ROOT, "steps", report["program"])):
            reports.append(report)
    claims = _json(os.path.join(out, "claims.json"), {})
    guides = claims.get("guides", {}) if isinstance(claims, dict) else {}
    decks = {os.path.basename(p)[:-5] for p in glob.glob(os.path.join(out, "slides", "*.html"))}
    # Every step report names its machine; reports copied together from two machines say so.
    machines = sorted({r.get("machine", "an unknown machine") for r in reports})
    machine = " and ".join(machines) if machines else "an unknown machine"
    counts = claims.get("counts") if isinstance(claims, dict) else None
    checked = ""
    if counts:
        checked = (f" What the READMEs and decks state about the measured outcomes: <b>{counts['agree']} "
                   f"agree</b> with this run, <b>{counts['fail']} do not</b>.")
    nav = " ".join(f"<a href='#{r['program']}'>{r['program']}</a>" for r in reports)
    slides = "<a href='slides/index.html'>the slides</a>" if os.path.exists(os.path.join(out, "slides", "index.html")) else ""
    parts = [step_html(out, r, guides.get(r["program"], {}), decks) for r in reports]
    page = f"""<!doctype html><html lang=en><head><meta charset=utf-8><title>Boxes workbook: the tour</title>
<meta name=viewport content="width=device-width, initial-scale=1"><style>{STYLE}</style></head>
<body><h1>Boxes workbook: the tour</h1>
<p>Every step run headless with <code>--measure</code> on {html.escape(machine)}. Each step says what it measured and what to
conclude, marks each point of its README's "What to look for" against this run (&#10004; agrees, &#10008; does not,
&#9675; not checked against the numbers), then shows its images, plots and tables, each with its takeaway.{checked}</p>
<nav><a href='#exercises'>exercises</a> {nav} {slides}</nav>
{exercises_html(out)}
{''.join(parts)}</body></html>"""
    with open(os.path.join(out, "index.html"), "w", encoding="utf-8") as f:
        f.write(page)
    print(f"[workbook] wrote {os.path.join(out, 'index.html')}", file=sys.stderr)


if __name__ == "__main__":
    main()
