"""The student's loop: build what changed, run the exercises' tests in order, show a table of
points and, for the first exercise that does not pass, what failed, where, and a hint; with
pictures of the student's render beside the reference (tools/pictures.py).

usage: ./workbook check [N.M | NN ...] [--hint] [--watch] [--timeout S] [--no-pictures]
       (python3 -m tools.check ..., from the tree's root; in the full tree and a starter kit)

  (nothing)   every exercise          N.M   one exercise        NN   one step's exercises
  --hint      the hint for the first exercise that does not pass (tests/hints/)
  --watch     run again whenever a file under steps/ changes (inotifywait, or polling)
  --timeout S the time limit of one exercise's tests (default 60 s)

An exercise is "not started" while its body is the kit's stub (it throws NotImplemented
with its own number), "needs N.M" when its tests stop at another exercise's stub, "passed"
when every test case passes, "failed" otherwise; "crashed", "timed out" and "does not
compile" say so. Exit 0 when every exercise that was attempted passes, 1 otherwise, 2 for a
bad command line. Results go to out/check/status.json (the tour's report reads it) and the
pictures to out/check/N.M.png.
"""
import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

from . import build as building
from .grading import ROOT
from .grading.exercises import MAX_RESULT_BYTES, exercises as marked_exercises, step_dirs

BUILD = os.path.join("build", "release")
OUT = os.path.join("out", "check")
HINTS = os.path.join("tests", "hints")
NOT_IMPLEMENTED = re.compile(r"exercise (\d+\.\d+) is not implemented yet")
# What a stub throws (core/exercise.hpp), shown when a test reports it.
STATUS_ORDER = ("passed", "failed", "crashed", "timed out", "does not compile", "needs",
                "not started", "no tests")


def say(text=""):
    print(text, flush=True)


# The selection --------------------------------------------------------------------------


def select(all_ex, words):
    """The exercises the words name ("1.4", "01", "1"), in order; raises ValueError."""
    if not words:
        return list(all_ex)
    chosen = []
    for w in words:
        if re.fullmatch(r"\d+\.\d+", w):
            found = [e for e in all_ex if e.id == w]
        elif re.fullmatch(r"\d{1,2}", w):
            found = [e for e in all_ex if e.step == int(w)]
        else:
            raise ValueError(f"'{w}' is neither an exercise (1.4) nor a step (01)")
        if not found:
            ids = ", ".join(e.id for e in all_ex)
            raise ValueError(f"no exercise or step '{w}' (exercises: {ids})")
        chosen += [e for e in found if e not in chosen]
    return sorted(chosen, key=lambda e: e.key)


def step_name(root, number):
    for d in step_dirs(root):
        name = os.path.basename(d)
        if int(name[:2]) == number:
            return name
    return None


# Building ---------------------------------------------------------------------------------


def first_compile_error(output, root):
    """The compiler's first error as "file:line: message", paths relative to the tree."""
    return building.first_error(output, root, brief=True)


def tree_of(root):
    return building.Tree.of_preset(root, "release")


def configure(root):
    """None, or the first error when the tree does not configure."""
    r = building.configure(tree_of(root), say=lambda text: say(f"[check] {text}"))
    return None if r.ok else r.error


def build_step(root, number, jobs=None):
    """Builds the step's test program (and its program, for the pictures), saying how far it
    has got; None or the first compile error."""
    target = f"test_step{number:02d}"
    say(f"[check] building step {number:02d} ({target} and what it needs; a first build takes minutes)")
    r = building.build(tree_of(root), [target], jobs, progress=building.Progress("[check]", sys.stdout))
    if not r.ok:
        return r.error
    if r.steps:
        say(f"[check]   {r.steps} build steps done in {r.seconds:.0f} s")
    return None


# Running one exercise's tests -------------------------------------------------------------


def run_suite(binary, exercise_id, timeout):
    """Runs the suite "exercise N.M" of a doctest program with its XML reporter. Returns
    (kind, xml bytes, detail): kind "ok", "crashed" (detail: the signal) or "timed out"."""
    with tempfile.TemporaryDirectory(prefix="boxes-check-") as tmp:
        out = os.path.join(tmp, "results.xml")
        cmd = [binary, f"--test-suite=exercise {exercise_id}", "--reporters=xml", f"--out={out}",
               "--no-version", "--no-intro"]
        # Its own process group: a timed-out test program is stopped with its children.
        p = subprocess.Popen(cmd, cwd=tmp, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             start_new_session=True)
        try:
            _, err = p.communicate(timeout=timeout)
            kind, detail = "ok", ""
            if p.returncode < 0:
                kind, detail = "crashed", signal.Signals(-p.returncode).name
            elif p.returncode not in (0, 1):
                kind, detail = "crashed", f"exit code {p.returncode}"
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.communicate()
            kind, detail, err = "timed out", f"{timeout:g} s", b""
        except BaseException:  # Ctrl-C or a signal: its own session does not get it
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()
            raise
        data = b""
        if os.path.exists(out):
            with open(out, "rb") as f:
                data = f.read(MAX_RESULT_BYTES)
        if kind == "crashed" and not detail.startswith("SIG"):
            tail = (err or b"").decode(errors="replace").strip().splitlines()[-1:]
            detail += f" ({tail[0]})" if tail else ""
        return kind, data, detail


def _text(el, tag):
    return " ".join((el.findtext(tag) or "").split())


def parse_cases(data):
    """[{name, file, line, passed, failure}] from doctest's XML; failure: the first failing
    check as {kind, expression, values, exception, infos, file, line} or None."""
    try:
        root = ET.fromstring(data)
    except ET.ParseError:
        return None
    cases = []
    for suite in root.iter("TestSuite"):
        for case in suite.findall("TestCase"):
            if case.get("skipped") == "true":
                continue
            res = case.find("OverallResultsAsserts")
            passed = (res is not None and res.get("failures", "0") == "0"
                      and res.get("test_case_success", "true") == "true"
                      and case.find("Exception") is None)
            failure = None
            if not passed:
                failure = first_failure(case)
            cases.append({"suite": suite.get("name", ""), "name": case.get("name", ""),
                          "file": case.get("filename", ""),
                          "line": case.get("line", ""), "passed": passed, "failure": failure})
    return cases


def first_failure(case):
    for el in case.iter():
        if el.tag == "Expression" and el.get("success") == "false":
            return {"kind": el.get("type", "CHECK"), "expression": _text(el, "Original"),
                    "values": _text(el, "Expanded"), "exception": _text(el, "Exception"),
                    "infos": [" ".join(i.text.split()) for i in el.findall("Info") if i.text],
                    "file": el.get("filename", ""), "line": el.get("line", "")}
        if el.tag == "Exception":
            return {"kind": "exception", "expression": "", "values": "", "infos": [],
                    "exception": " ".join((el.text or "").split()), "file": "", "line": ""}
        if el.tag == "Message" and el.get("type", "").upper() in ("FAIL", "FAIL_CHECK", "ERROR"):
            return {"kind": "message", "expression": "", "values": _text(el, "Text"),
                    "exception": "", "infos": [], "file": el.get("filename", ""),
                    "line": el.get("line", "")}
    return {"kind": "unknown", "expression": "", "values": "", "exception": "", "infos": [],
            "file": "", "line": ""}


def classify(exercise_id, cases, mistakes=None):
    """(status, the failing case to show or None) for one exercise's test cases: the first
    failing case, or the first that exists for a catalogued mistake of this exercise
    (`mistakes`: tests/hints/mistakes.json), whose hint says more than the exercise's."""
    if not cases:
        return "no tests", None
    failing = [c for c in cases if not c["passed"]]
    if not failing:
        return "passed", None
    missing = []
    for c in failing:
        f = c["failure"] or {}
        m = NOT_IMPLEMENTED.search(f.get("exception", "") + " " + f.get("values", ""))
        missing.append(m.group(1) if m else None)
    if exercise_id in missing:
        return "not started", failing[missing.index(exercise_id)]
    real = [c for c, m in zip(failing, missing) if m is None]
    if real:
        own = [c for c in real if (mistakes or {}).get(c["name"], {}).get("exercise") == exercise_id]
        return "failed", (own or real)[0]
    return "needs " + ", ".join(sorted(set(missing), key=lambda s: tuple(map(int, s.split("."))))), failing[0]


def last_case_started(data):
    names = re.findall(rb'<TestCase name="([^"]*)"', data or b"")
    return names[-1].decode(errors="replace") if names else ""


# Hints ------------------------------------------------------------------------------------


def load_hints(root):
    def load(name):
        try:
            with open(os.path.join(root, HINTS, name), encoding="utf-8") as f:
                value = json.load(f)
            return value if isinstance(value, dict) else {}
        except (OSError, ValueError):
            return {}

    return load("exercises.json"), load("mistakes.json")


def hint_for(row, hints):
    """The mistake's hint when the failing test case is a catalogued mistake of this
    exercise, else the exercise's hint."""
    generic, mistakes = hints
    case = (row.get("case") or {}).get("name")
    m = mistakes.get(case) if case else None
    if isinstance(m, dict) and m.get("hint") and m.get("exercise", row["id"]) == row["id"]:
        return m["hint"], True
    return generic.get(row["id"], ""), False


# One run ----------------------------------------------------------------------------------


def check_once(root, chosen, opts):
    rows, built = [], {}
    mistakes = load_hints(root)[1]
    problem = configure(root)
    for e in chosen:
        row = {"id": e.id, "title": e.title, "points": e.points, "earned": 0, "step": e.step,
               "where": f"{e.path}:{e.marker_line + 1}", "case": None, "detail": "",
               "cases": 0, "failed": 0}
        rows.append(row)
        if problem:
            row["status"], row["detail"] = "does not compile", problem
            continue
        if e.step not in built:
            built[e.step] = build_step(root, e.step, opts.jobs)
        if built[e.step]:
            row["status"], row["detail"] = "does not compile", built[e.step]
            continue
        binary = os.path.join(root, BUILD, "tests", f"test_step{e.step:02d}")
        kind, data, detail = run_suite(binary, e.id, opts.timeout)
        cases = parse_cases(data) if data else None
        if kind != "ok":
            row["status"] = kind
            case = last_case_started(data)
            row["detail"] = f"{detail} in test case \"{case}\"" if case else detail
            row["case"] = {"name": case, "failure": None, "file": "", "line": ""} if case else None
            continue
        if cases is None:
            row["status"], row["detail"] = "crashed", "no test results were written"
            continue
        row["status"], row["case"] = classify(e.id, cases, mistakes)
        row["cases"], row["failed"] = len(cases), sum(not c["passed"] for c in cases)
        if row["status"] == "passed":
            row["earned"] = e.points
    return rows


def attempted(row):
    return not (row["status"] == "not started" or row["status"].startswith("needs"))


def print_table(rows, everything):
    say()
    say(f"  {'exercise':<9}{'points':>7}  status")
    for r in rows:
        status = r["status"]
        if status == "failed":
            status += f" ({r['failed']} of {r['cases']} test cases)"
        elif status in ("crashed", "timed out", "does not compile"):
            status += f": {r['detail']}"
        if len(status) > 90:
            status = status[:87] + "..."
        say(f"  {r['id']:<9}{str(r['earned']) + '/' + str(r['points']):>7}  {status}")
    earned, total = sum(r["earned"] for r in rows), sum(r["points"] for r in rows)
    scope = "" if everything else " (the exercises checked)"
    say(f"  {'total':<9}{str(earned) + '/' + str(total):>7}  points{scope}")
    return earned, total


def describe_failure(row, root):
    """The lines that say what failed, in plain words."""
    lines = []
    c = row.get("case")
    status = row["status"]
    if status == "not started":
        lines.append(f"  not started: its body is still the kit's stub (throw NotImplemented(\"{row['id']}\")).")
        lines.append("  Replace the stub with your solution; the step's README explains the exercise.")
        return lines
    if status.startswith("needs"):
        need = status.split(" ", 1)[1]
        lines.append(f"  its tests use exercise {need}, which is not started yet: solve {need} first.")
        if c:
            lines.append(f"  (test case \"{c['name']}\")")
        return lines
    if status == "does not compile":
        lines.append(f"  does not compile: {row['detail']}")
        return lines
    if status in ("crashed", "timed out"):
        what = "crashed" if status == "crashed" else "did not finish within the time limit"
        lines.append(f"  the tests {what}: {row['detail']}")
        if status == "timed out":
            lines.append("  (an endless loop? --timeout S gives the tests longer)")
        return lines
    if status == "no tests":
        lines.append("  no test case ran for this exercise (its suite is missing from tests/)")
        return lines
    if not c:
        return lines
    where = f"{c['file']}:{c['line']}" if c.get("file") else ""
    lines.append(f"  failing test case: \"{c['name']}\"" + (f" ({_rel(where, root)})" if where else ""))
    f = c.get("failure") or {}
    if f.get("expression"):
        at = f" at {_rel(f['file'] + ':' + f['line'], root)}" if f.get("file") else ""
        lines.append(f"  the check {f['kind']}( {f['expression']} ) failed{at}")
        if f.get("exception"):
            lines.append(f"    it threw: {f['exception']}")
        elif f.get("values") and f["values"] != f["expression"]:
            lines.append(f"    with the values: {f['values']}")
    elif f.get("exception"):
        lines.append(f"  the test threw: {f['exception']}")
    elif f.get("values"):
        lines.append(f"  {f['values']}")
    for info in f.get("infos", []):
        lines.append(f"    input: {info}")
    return lines


def _rel(where, root):
    """A test's file:line relative to the tree (doctest gives it relative to the build)."""
    path, _, line = where.rpartition(":")
    full = path if os.path.isabs(path) else os.path.normpath(os.path.join(root, BUILD, path))
    rel = os.path.relpath(full, root)
    if not rel.startswith(".."):
        path = rel
    return f"{path}:{line}"


def report(rows, root, opts, everything):
    earned, total = print_table(rows, everything)
    hints = load_hints(root)
    first = next((r for r in rows if r["status"] != "passed"), None)
    from . import pictures  # noqa: PLC0415 (the pictures are optional; a failure there is said)

    shown = {}
    if not opts.no_pictures:
        try:
            shown = pictures.make(root, rows, first, os.path.join(root, OUT), say)
        except Exception as exc:  # a picture must never hide the table
            say(f"[check] the pictures failed: {exc}")
    say()
    if first is None:
        say("  Every exercise checked passes." + (" Well done." if everything else ""))
    else:
        say(f"Next: exercise {first['id']}: {first['title']} ({first['points']} point"
            f"{'s' if first['points'] != 1 else ''})")
        say(f"  where: {first['where']}")
        for line in describe_failure(first, root):
            say(line)
        pic = shown.get(first["id"])
        if pic:
            say(f"  picture: {pic}")
        hint, specific = hint_for(first, hints)
        if opts.hint:
            if hint:
                say(f"  hint{' (this mistake)' if specific else ''}: {hint}")
            else:
                say("  (no hint written for this exercise)")
        elif hint:
            say("  a hint: ./workbook check --hint" + (f" {first['id']}" if not everything else ""))
    write_status(root, rows, shown)
    failing = [r for r in rows if attempted(r) and r["status"] != "passed"]
    return 0 if not failing else 1


def write_status(root, rows, shown):
    os.makedirs(os.path.join(root, OUT), exist_ok=True)
    data = {"time": time.strftime("%Y-%m-%d %H:%M:%S"),
            "exercises": [{k: r[k] for k in ("id", "title", "points", "earned", "status", "where",
                                            "detail")}
                          | {"case": (r.get("case") or {}).get("name"),
                             "picture": shown.get(r["id"])} for r in rows]}
    with open(os.path.join(root, OUT, "status.json"), "w", encoding="utf-8") as f:
        json.dump(data, f, indent=1)


# Watching ---------------------------------------------------------------------------------


def snapshot(root):
    stamp = {}
    for d in step_dirs(root):
        for base, _, files in os.walk(d):
            for name in files:
                path = os.path.join(base, name)
                try:
                    st = os.stat(path)
                except OSError:
                    continue
                stamp[path] = (st.st_mtime_ns, st.st_size)
    return stamp


def wait_for_change(root, poll):
    """Returns when a file under steps/ changes: inotifywait when installed, else polling
    every half second."""
    tool = shutil.which("inotifywait")
    if tool and not poll:
        steps = os.path.join(root, "steps")
        r = subprocess.run([tool, "-q", "-r", "-e", "close_write,moved_to,create,delete",
                            "--format", "%w%f", steps],
                           stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        if r.returncode in (0, 2):  # 2: the timeout, which is not set here
            time.sleep(0.1)  # an editor writes a file in more than one step
            return r.stdout.strip().splitlines()[0] if r.stdout.strip() else os.path.join(root, "steps")
    before = snapshot(root)
    while True:
        time.sleep(0.5)
        now = snapshot(root)
        if now != before:
            changed = sorted(set(now.items()) ^ set(before.items()))
            return changed[0][0] if changed else os.path.join(root, "steps")


def watch(root, chosen, opts, everything):
    how = "inotifywait" if shutil.which("inotifywait") and not opts.poll else "polling every 0.5 s"
    changed = None
    while True:
        sys.stdout.write("\033[2J\033[H")  # clear the screen
        sys.stdout.flush()
        if changed is not None:
            say(f"[check] {os.path.relpath(changed, root)} changed: checking again")
        rows = check_once(root, chosen, opts)
        report(rows, root, opts, everything)
        say()
        say(f"[check] watching steps/ for changes ({how}; Ctrl-C stops)")
        changed = wait_for_change(root, opts.poll)


def main(argv, root=ROOT):
    p = argparse.ArgumentParser(prog="./workbook check",
                                description="run the exercises' tests in order, with a hint and pictures")
    p.add_argument("which", nargs="*", help="an exercise (1.4) or a step (01); default: all")
    p.add_argument("--hint", action="store_true", help="print the hint for the next exercise")
    p.add_argument("--watch", action="store_true", help="check again whenever a step's file changes")
    p.add_argument("--poll", action="store_true", help="--watch by polling, without inotifywait")
    p.add_argument("--timeout", type=float, default=60.0, help="seconds for one exercise's tests")
    p.add_argument("--jobs", type=int, default=None, help="build jobs (default: the build's own)")
    p.add_argument("--no-pictures", action="store_true", help="no pictures (faster)")
    opts = p.parse_args(argv)
    if not opts.timeout > 0:
        p.error("--timeout must be positive")
    all_ex = marked_exercises(root)
    if not all_ex:
        print("check: no exercise markers under steps/ (is this the workbook's root?)", file=sys.stderr)
        return 2
    try:
        chosen = select(all_ex, opts.which)
    except ValueError as exc:
        print(f"check: {exc}", file=sys.stderr)
        return 2
    everything = not opts.which

    def stop(signum, _frame):  # as Ctrl-C: the temporary folders and the test program go
        raise KeyboardInterrupt(signum)

    for sig in (signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, stop)
    try:
        if opts.watch:
            watch(root, chosen, opts, everything)
        rows = check_once(root, chosen, opts)
        return report(rows, root, opts, everything)
    except KeyboardInterrupt as stopped:
        say()
        return 128 + (stopped.args[0] if stopped.args else signal.SIGINT)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
