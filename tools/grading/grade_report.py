"""The grade's report: a row per exercise, the points table on the terminal, the JUnit XML,
the JSON, the rows as the class grader and Gradescope keep them, and every text that came
from student code made printable on the way."""
import json
import os
import re
import sys
import xml.etree.ElementTree as ET


# What XML 1.0 forbids (C0 controls but tab and newline here, also carriage return; U+FFFE,
# U+FFFF; lone surrogates), and DEL and the C1 controls, which drive terminals.
_UNPRINTABLE = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\ud800-\udfff\ufffe\uffff]")


def printable(text):
    """text with each such character written as \\xNN or \\uNNNN: what the student's code prints,
    throws or names goes into the JUnit XML (which must stay well-formed), the JSON and the
    instructor's terminal."""
    return _UNPRINTABLE.sub(lambda m: f"\\x{ord(m.group()):02x}" if ord(m.group()) < 0x100
                            else f"\\u{ord(m.group()):04x}", text)


# Bidirectional controls: they reorder what a terminal or a spreadsheet shows around them.
_BIDI = re.compile("[\u200e\u200f\u202a-\u202e\u2066-\u2069]")


def one_line(text):
    """printable(text) on one line, for a name (a student's, an archive member's) in a
    progress line or a table cell: newlines, tabs and bidirectional controls written as
    escapes too, so a name can neither run a terminal's escape sequences nor forge a line."""
    text = printable(str(text)).replace("\n", "\\n").replace("\t", "\\t")
    return _BIDI.sub(lambda m: f"\\u{ord(m.group()):04x}", text)


def say(text, log=None):
    print(f"[grade] {text}", file=log or sys.stderr, flush=True)


def exercise_row(e, number, build_error, outcomes, seconds, hidden=0):
    """The report's row of one exercise: passed when it has test cases and all pass; else the
    reason of its first failing case, of its step's build ('does not compile: ...'), or
    (status, reason) of a test program that does not start. `hidden`: how many of the
    exercise's cases are the instructor's hidden tests (whether they ran or not);
    public_details and public_passed say how its other cases went, nothing of the hidden."""
    failed = [o for o in outcomes if not o.passed]
    if isinstance(build_error, tuple):  # the test program does not start
        (status, reason), case = build_error, ""
    elif build_error:
        status, reason, case = "does not compile", build_error, ""
    elif not outcomes:
        status, reason, case = "no tests", "no test cases for this exercise", ""
    elif failed:
        status, reason, case = failed[0].status, failed[0].reason, failed[0].name
    else:
        status, reason, case = "passed", "", ""
    reason = printable(reason)
    reason = reason if len(reason) <= 500 else reason[:497] + "..."
    message = reason + (f' (test case "{case}")' if case else "")
    def line(o):
        return printable(f"{'passed' if o.passed else 'FAILED'}: {o.name}" + ("" if o.passed else f": {o.reason}"))

    details = [line(o) for o in outcomes] or [message]
    public = [o for o in outcomes if not getattr(o, "hidden", False)]
    return {"id": e.id, "title": e.title, "points": e.points, "step": number,
            "passed": status == "passed", "status": status, "reason": reason, "case": case,
            "message": message, "details": details, "hidden": hidden,
            "public_details": [line(o) for o in public] or ([message] if build_error else []),
            "public_passed": bool(public) and all(o.passed for o in public),
            "seconds": sum(o.seconds for o in outcomes) if outcomes else seconds}


def print_table(rows, notes, out=sys.stdout):
    total = sum(r["points"] for r in rows)
    earned = sum(r["points"] for r in rows if r["passed"])
    out.write(f"\nGrade: {earned} of {total} points\n\n")
    out.write(f"{'exercise':<9} {'points':>6}  {'result':<7} why it failed\n")
    for r in rows:
        got = r["points"] if r["passed"] else 0
        out.write(f"{r['id']:<9} {got:>2} / {r['points']:<2}  {'passed' if r['passed'] else 'FAILED':<7} "
                  f"{r['message']}\n")
    for n in notes:
        out.write(f"note: {n}\n")
    out.flush()
    return earned, total


def write_junit(path, rows, notes, seconds):
    failures = sum(1 for r in rows if not r["passed"])
    suites = ET.Element("testsuites", name="boxes grading", tests=str(len(rows)),
                        failures=str(failures), time=f"{seconds:.1f}")
    by_step = {}
    for r in rows:
        by_step.setdefault(r["step"], []).append(r)
    for step, items in sorted(by_step.items()):
        s = ET.SubElement(suites, "testsuite", name=f"step {step}", tests=str(len(items)),
                          failures=str(sum(1 for r in items if not r["passed"])))
        props = ET.SubElement(s, "properties")
        ET.SubElement(props, "property", name="points",
                      value=str(sum(r["points"] for r in items if r["passed"])))
        ET.SubElement(props, "property", name="points_possible", value=str(sum(r["points"] for r in items)))
        for r in items:
            c = ET.SubElement(s, "testcase", classname=f"exercise {r['id']}",
                              name=f"exercise {r['id']}: {r['title']} ({r['points']} point{'s' if r['points'] != 1 else ''})",
                              time=f"{r['seconds']:.2f}")
            if not r["passed"]:
                f = ET.SubElement(c, "failure", message=printable(r["message"]), type="failed")
                f.text = printable("\n".join(r["details"]) or r["message"])
            else:
                ET.SubElement(c, "system-out").text = printable("\n".join(r["details"]))
        earned = sum(r["points"] for r in items if r["passed"])
        ET.SubElement(s, "system-out").text = (
            f"step {step}: {earned} of {sum(r['points'] for r in items)} points\n" +
            "".join(f"note: {printable(n)}\n" for n in notes))
    ET.indent(suites)
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    ET.ElementTree(suites).write(path, encoding="utf-8", xml_declaration=True)


def write_json(path, rows, notes, seconds):
    """The per-exercise results as JSON, for batch grading and other tools: one object per
    exercise with its points earned (0 unless passed), max, status (passed, failed, time
    limit, memory limit, output limit, crashed, does not compile, no tests), reason (empty
    when passed), the first failing test case, details (a line per test case: how it went),
    hidden (how many of its cases are the instructor's hidden tests) and seconds."""
    doc = {"points": sum(r["points"] for r in rows if r["passed"]),
           "max": sum(r["points"] for r in rows), "seconds": round(seconds, 2),
           "exercises": [{"exercise": r["id"], "title": r["title"], "step": r["step"],
                          "points": r["points"] if r["passed"] else 0, "max": r["points"],
                          "status": r["status"], "reason": r["reason"], "case": r["case"],
                          "details": list(r["details"]), "hidden": r.get("hidden", 0),
                          "seconds": round(r["seconds"], 2)}
                         for r in rows],
           "notes": list(notes)}
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", encoding="utf-8") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")


def results_by_exercise(rows):
    """The rows as the class grader and Gradescope keep them, one dict per exercise:
    exercise, title, step, max, passed, points (earned), status, reason (with the first
    failing test case in front), details (a line per test case), hidden (how many cases are
    hidden tests), public_details and public_passed (the other cases only), seconds."""
    results = []
    for r in rows:
        reason = r["reason"]
        if r["case"] and not r["passed"] and r["case"] not in reason:
            reason = f"{r['case']}: {reason}"
        details = "\n".join(r["details"]) or r["message"]
        results.append({"exercise": r["id"], "title": r["title"], "step": r["step"], "max": r["points"],
                        "passed": r["passed"], "points": r["points"] if r["passed"] else 0,
                        "status": r["status"], "reason": reason,
                        "details": [line for line in details.splitlines() if line.strip()],
                        "hidden": r.get("hidden", 0), "public_details": r.get("public_details", []),
                        "public_passed": r.get("public_passed", False),
                        "seconds": round(r["seconds"], 2)})
    return results
