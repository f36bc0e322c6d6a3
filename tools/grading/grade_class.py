"""Grades a whole class: a folder with one submission per student (a folder, a git
repository or a .zip/.tar.* archive), in parallel, with the single-tree grader.

usage: ./workbook grade-class SUBMISSIONS [--out DIR] [--jobs N] [--hidden DIR]
                              [--steps 01,02] [--timeout S] [--student-timeout S]
       (python3 -m tools.grading.grade_class ..., from the repository root)

Each submission is reduced to its step sources (submissions.py: safe unpacking, size
limits) and graded by grade.py, called in-process on a thread per job. Every worker (--jobs,
default the number of cores) has its own grading folder (OUT/work/wN), primed once with the
reference tree and reused for every student it grades, so a student costs the compile of
their own step sources and the relink, not a build of the whole workbook.

Written into OUT (default build/class-grades/): class.csv (student, points per exercise, total,
build status, seconds), students/NAME/ (the points table, the JUnit XML, grade.json,
grade.log, result.json), index.html (the distribution of points per exercise as a table and
a plot, and the most common first failure per exercise) and cache.json. Progress goes to
stderr. A run can be stopped (Ctrl-C) and started again: a submission whose graded sources
hash to the same value as before (with the same reference, hidden tests and options) keeps
its result and is not graded again.
"""
import argparse
import collections
import csv
import fcntl
import hashlib
import html
import json
import os
import signal
import sys
import threading
import time
import traceback
from concurrent.futures import ThreadPoolExecutor, as_completed

from . import ROOT, sandbox
from .strict_numbers import MAX_JOBS, MAX_SECONDS, decimal, integer, step_list
from .cgroups import usable_cpus
from .errors import NOT_GRADED_EXIT
from .exercises import exercises
from .grade import GradeOptions, grade_into
from .grade_report import one_line
from .kit import tracked_files
from .submissions import SubmissionError, content_hash, is_submission, read_submission, stage, student_name

CACHE_VERSION = 1
# What in tools/ decides a grade (besides the reference's sources, tests and CMake files).
GRADER_FILES = ("tools/grading/grade.py", "tools/grading/grade_report.py", "tools/grading/grading_tree.py",
                "tools/grading/box.py", "tools/grading/build_and_run.py", "tools/grading/errors.py",
                "tools/grading/exercises.py", "tools/grading/kit.py", "tools/grading/sandbox",
                "tools/grading/submissions.py", "tools/grading/judge/")


def say(text):
    """A progress line: a student's or a file's name in it is escaped (one_line)."""
    print(f"[class] {one_line(text)}", file=sys.stderr, flush=True)


def run_grader(tree, work, report_dir, steps=None, hidden=None, timeout=60.0, jobs=1,
               no_sandbox=False, limit=None, user=None, partial=False, judge=None):
    """Grades one tree in-process into report_dir (points.txt, grade.log, grade.xml,
    grade.json) in the grading folder `work`; returns grade.Report (code None: it ran out of
    `limit` seconds; with `partial` the exercises not graded by then fail instead). `user`:
    without the sandbox, as root, the unprivileged user student code runs as. `judge`: the
    checkers' folder (default WORK/judge); the class's grading folders share one."""
    opts = GradeOptions(work=work, timeout=timeout, jobs=jobs, steps=steps, hidden=hidden,
                        no_isolation=no_sandbox, user=user, judge=judge)
    return grade_into(report_dir, tree, opts, limit, partial)


# The class --------------------------------------------------------------------------------


def config_hash(hidden, steps, timeout):
    """What a grade depends on besides the student: the reference tree (tests, core, CMake,
    grader), the hidden tests and the options."""
    h = hashlib.sha256(f"v{CACHE_VERSION} steps={steps} timeout={timeout:g}\n".encode())
    for rel in sorted(tracked_files(ROOT)):
        if rel.startswith(("slides/", "out/", ".ci/", "tests/tools/")) or rel.endswith((".md", "_test.py")):
            continue
        if rel.startswith("tools/") and not rel.startswith(GRADER_FILES):
            continue  # the class grader, the kit's extras, the report: not what grades
        with open(os.path.join(ROOT, rel), "rb") as f:
            h.update(rel.encode() + b"\0" + hashlib.sha256(f.read()).digest())
    if hidden:
        for n in sorted(os.listdir(hidden)):
            p = os.path.join(hidden, n)
            if os.path.isfile(p):
                with open(p, "rb") as f:
                    h.update(b"hidden/" + n.encode() + b"\0" + hashlib.sha256(f.read()).digest())
    return h.hexdigest()


class Workers:
    """The grading folders OUT/work/wN, one per worker, each locked (flock) while this class
    grader runs, so a second one on the same folders waits."""

    def __init__(self, root, count):
        self.root, self.free, self.cv = root, list(range(count)), threading.Condition()
        self.fds = {}
        for i in range(count):
            os.makedirs(self.dir(i), exist_ok=True)
            fd = os.open(os.path.join(self.dir(i), "lock"), os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                say(f"waiting for {self.dir(i)}: another grader still uses it")
                fcntl.flock(fd, fcntl.LOCK_EX)
            self.fds[i] = fd

    def dir(self, i):
        return os.path.join(self.root, f"w{i}")

    def judge(self):
        """The checkers' folder every worker shares: built once for the class."""
        return os.path.join(self.root, "judge")

    def take(self):
        with self.cv:
            while not self.free:
                self.cv.wait()
            return self.free.pop(0)

    def give(self, i):
        with self.cv:
            self.free.append(i)
            self.cv.notify()

    def close(self):
        for fd in self.fds.values():
            os.close(fd)


def prime(workers, count, opts, key):
    """Grades the reference tree in every worker folder that is not primed for this
    configuration, in parallel: the core and the tests get built once per folder. Returns
    the reference's result (it must have full points)."""
    todo = []
    for i in range(count):
        stamp = os.path.join(workers.dir(i), "primed")
        if not (os.path.exists(stamp) and open(stamp).read().strip() == key):
            todo.append(i)
    if not todo:
        return None
    say(f"priming {len(todo)} grading folder(s) with the reference tree (the core and the tests "
        "are built once per folder; a few minutes)")
    results = {}

    def one(i):
        report = os.path.join(workers.dir(i), "reference")
        r = run_grader(ROOT, workers.dir(i), report, opts.steps, opts.hidden, opts.timeout,
                       opts.compile_jobs, opts.no_sandbox, judge=workers.judge())
        rows = r.results if r.code == 0 else None
        results[i] = (r.code, rows, r.seconds)
        if r.code == 0 and rows and all(x["passed"] for x in rows):
            with open(os.path.join(workers.dir(i), "primed"), "w") as f:
                f.write(key + "\n")

    with ThreadPoolExecutor(len(todo)) as pool:
        try:
            list(pool.map(one, todo))
        except KeyboardInterrupt:  # the pool's threads stop with their sandboxed commands
            sandbox.stop_all()
            raise
    for i, (code, rows, seconds) in results.items():
        if code != 0 or not rows or not all(r["passed"] for r in rows):
            failed = [f"{r['exercise']} ({r['reason']})" for r in rows or [] if not r["passed"]]
            raise SystemExit(f"grade-class: the reference tree does not get full points in "
                             f"{workers.dir(i)} (exit {code}; {', '.join(failed) or 'no results'}); "
                             f"see {workers.dir(i)}/reference/")
        say(f"primed {workers.dir(i)} in {seconds:.0f} s (the reference: full points)")
    return results


RETRY = ", retry"  # ends the reason of a row the grading machine failed (nothing cached)


def grade_one(sub, workers, opts):
    """Grades one submission: {student, hash, status, build, rows, total, seconds, ...}.
    Whatever goes wrong with it (its archive, staging it, the grader) is its own row's
    reason, "not graded: ...": the class goes on."""
    result = {"student": sub["student"], "source": sub["entry"], "hash": sub["hash"], "seconds": 0.0}
    if sub.get("error"):
        result.update(status="error", build=f"not graded: {sub['error']}", rows=[], total=0)
        return result
    try:
        return _grade_one(sub, workers, opts, result)
    except sandbox.Stopped:
        raise
    except Exception as e:  # a failure of the grader or the machine, not a grade
        traceback.print_exc()
        why = f"{type(e).__name__}: {e}" if not isinstance(e, OSError) else str(e)
        result.update(status="error", build=f"not graded: the grader failed ({why[:200]}){RETRY}",
                      rows=[], total=0)
        return result


def _grade_one(sub, workers, opts, result):
    report = os.path.join(opts.out, "students", sub["student"])
    i = workers.take()
    try:
        try:
            tree = stage(sub["files"], os.path.join(workers.dir(i), "student"))
        except SubmissionError as e:
            result.update(status="error", build=f"not graded: {e}", rows=[], total=0)
            return result
        except OSError as e:
            result.update(status="error", build=f"not graded: staging failed ({e}){RETRY}", rows=[], total=0)
            return result
        r = run_grader(tree, workers.dir(i), report, opts.steps, opts.hidden, opts.timeout,
                       opts.compile_jobs, opts.no_sandbox, opts.student_timeout, judge=workers.judge())
    finally:
        workers.give(i)
    result["seconds"] = round(r.seconds, 2)
    if r.code is None:
        result.update(status="error", build=f"grading ran out of time ({opts.student_timeout:g} s)", rows=[])
    elif r.code == NOT_GRADED_EXIT:
        result.update(status="error", build=f"{r.last_line[:300]}{RETRY}", rows=[])
    elif r.code != 0:
        result.update(status="error", build=f"the grader failed (exit {r.code}): {r.last_line[:200]}", rows=[])
    else:
        rows = r.results
        broken = sorted({x["step"] for x in rows if x["status"] == "does not compile"})
        result.update(status="graded", rows=rows,
                      build="ok" if not broken else "step " + ",".join(broken) + " does not compile")
    result["total"] = sum(r["points"] for r in result["rows"])
    os.makedirs(report, exist_ok=True)
    with open(os.path.join(report, "result.json"), "w") as f:
        json.dump(result, f, indent=1)
    return result


def discover(folder):
    """[{student, entry, path}] of the submissions in a folder, by name."""
    subs, names = [], set()
    for entry in sorted(os.listdir(folder)):
        path = os.path.join(folder, entry)
        if entry.startswith(".") or not is_submission(path):
            continue
        name = student_name(entry)
        if name in names or not name:
            name = entry
        names.add(name)
        subs.append({"student": name, "entry": entry, "path": path})
    return subs


def cell(text):
    """A text cell of class.csv: on one line, escaped (one_line), and never a formula (a
    spreadsheet runs a cell that starts with = + - @: a quote in front keeps it text)."""
    text = one_line(text)
    return "'" + text if text[:1] in ("=", "+", "-", "@") else text


def write_csv(path, results, ex_list):
    with open(path + ".tmp", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["student"] + [e.id for e in ex_list] + ["total", "max", "build", "seconds"])
        maximum = sum(e.points for e in ex_list)
        for r in sorted(results, key=lambda r: r["student"]):
            got = {row["exercise"]: row["points"] for row in r["rows"]}
            w.writerow([cell(r["student"])] + [got.get(e.id, 0) for e in ex_list] +
                       [r.get("total", 0), maximum, cell(r["build"]), f"{r.get('seconds', 0):.1f}"])
    os.replace(path + ".tmp", path)


def write_summary(out, results, ex_list):
    """index.html: per exercise the distribution of points (table and plot) and the most
    common first failure."""
    n = len(results)
    graded = [r for r in results if r["status"] == "graded"]
    rows_html, fractions = [], []
    for e in ex_list:
        got = [next((x for x in r["rows"] if x["exercise"] == e.id), None) for r in graded]
        full = sum(1 for x in got if x and x["passed"])
        reasons = collections.Counter()
        for x in got:
            if x and not x["passed"] and x["reason"]:
                reasons[x["reason"]] += 1
        common = reasons.most_common(1)
        fractions.append((e.id, full, len(graded) - full))
        mean = sum(x["points"] for x in got if x) / len(graded) if graded else 0.0
        rows_html.append(
            f"<tr><td>{e.id}</td><td class=t>{html.escape(e.title)}</td><td>{e.points}</td>"
            f"<td>{full}</td><td>{len(graded) - full}</td><td>{mean:.2f}</td>"
            f"<td class=t>{html.escape(common[0][0]) + f' <i>({common[0][1]}&times;)</i>' if common else ''}</td></tr>")
    totals = [r.get("total", 0) for r in graded]
    maximum = sum(e.points for e in ex_list)
    plot = ""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (a, b) = plt.subplots(1, 2, figsize=(12, max(3.5, 0.3 * len(ex_list))))
        ids = [f[0] for f in fractions][::-1]
        a.barh(ids, [f[1] for f in fractions][::-1], color="#4a8", label="full points")
        a.barh(ids, [f[2] for f in fractions][::-1], left=[f[1] for f in fractions][::-1],
               color="#d65", label="zero")
        a.set_xlabel("students")
        a.set_title("points per exercise")
        a.legend(loc="upper center", bbox_to_anchor=(0.5, -0.15), ncol=2, frameon=False)
        a.xaxis.get_major_locator().set_params(integer=True)
        b.hist(totals, bins=range(0, maximum + 2), color="#48c", align="left")
        b.set_xlabel(f"total points (of {maximum})")
        b.set_ylabel("students")
        b.set_title("total points")
        b.yaxis.get_major_locator().set_params(integer=True)
        fig.tight_layout()
        fig.savefig(os.path.join(out, "points.png"), dpi=90)
        plt.close(fig)
        plot = '<p><img src="points.png" alt="points per exercise and total points"></p>'
    except ImportError:
        plot = "<p>(no plot: python3-matplotlib is missing; tools/deps.sh report)</p>"
    failed_build = sum(1 for r in graded if r["build"] != "ok")
    errors = [r for r in results if r["status"] != "graded"]
    page = f"""<!doctype html><meta charset="utf-8"><title>Class grades</title>
<style>body{{font:14px sans-serif;margin:2em}}td,th{{padding:2px 8px;text-align:right}}
td.t{{text-align:left}}table{{border-collapse:collapse}}tr:nth-child(even){{background:#f4f4f4}}</style>
<h1>Class grades</h1>
<p>{n} submissions: {len(graded)} graded ({failed_build} with a step that does not compile),
{len(errors)} not graded. Mean total {sum(totals) / len(totals) if totals else 0:.1f} of {maximum};
median {sorted(totals)[len(totals) // 2] if totals else 0}. The table per student: <a href="class.csv">class.csv</a>.</p>
{plot}
<h2>Per exercise</h2>
<table><tr><th>exercise</th><th class=t>what</th><th>points</th><th>full points</th><th>zero</th>
<th>mean</th><th class=t>most common first failure</th></tr>
{''.join(rows_html)}</table>
{'<h2>Not graded</h2><ul>' + ''.join(f'<li>{html.escape(one_line(r["student"]))}: {html.escape(one_line(r["build"]))}</li>' for r in errors) + '</ul>' if errors else ''}
"""
    with open(os.path.join(out, "index.html"), "w") as f:
        f.write(page)


def grade_class(opts):
    started = time.monotonic()
    opts.out = os.path.abspath(opts.out)
    os.makedirs(os.path.join(opts.out, "students"), exist_ok=True)
    all_ex = exercises(ROOT)
    numbers = sorted({f"{e.step:02d}" for e in all_ex})
    if isinstance(opts.steps, str):  # a caller's "01,02" rather than the command line's list
        opts.steps = step_list(opts.steps)
    opts.steps = opts.steps or None
    bad = [s for s in opts.steps or [] if s not in numbers]
    if bad:
        raise SystemExit(f"grade-class: --steps {','.join(bad)}: no such step (steps: {','.join(numbers)})")
    ex_list = [e for e in all_ex if not opts.steps or f"{e.step:02d}" in opts.steps]
    opts.all_ex = {e.id: e for e in all_ex}
    opts.hidden = os.path.abspath(opts.hidden) if opts.hidden else None
    opts.jobs = max(1, opts.jobs)
    opts.compile_jobs = max(1, usable_cpus() // opts.jobs)
    key = config_hash(opts.hidden, opts.steps, opts.timeout)

    subs = discover(opts.submissions)
    if not subs:
        raise SystemExit(f"grade-class: no submissions (folders or archives) in {opts.submissions}")
    for s in subs:
        try:
            s["files"] = read_submission(s["path"])
            s["hash"] = content_hash(s["files"])
        except SubmissionError as e:
            s["error"], s["hash"] = str(e), ""
        except Exception as e:  # an archive Python cannot read (encrypted, a broken stream)
            s["error"], s["hash"] = f"cannot be read ({type(e).__name__}: {str(e)[:200]}){RETRY}", ""

    cache_path = os.path.join(opts.out, "cache.json")
    cache = {}
    if os.path.exists(cache_path) and not opts.no_cache:
        try:
            with open(cache_path) as f:
                doc = json.load(f)
            if doc.get("config") == key:
                cache = doc.get("results", {})
            else:
                say("the reference, hidden tests or options changed: grading every submission again")
        except (OSError, ValueError):
            pass
    results, todo = {}, []
    for s in subs:
        old = cache.get(s["student"])
        if old and old.get("hash") == s["hash"] and s["hash"] and old.get("status") == "graded":
            results[s["student"]] = old
        else:
            todo.append(s)
    say(f"{len(subs)} submissions: {len(results)} unchanged since the last run, {len(todo)} to grade "
        f"with {opts.jobs} job(s)")
    lock = threading.Lock()

    def save():
        with open(cache_path + ".tmp", "w") as f:
            json.dump({"config": key, "results": results}, f)
        os.replace(cache_path + ".tmp", cache_path)
        write_csv(os.path.join(opts.out, "class.csv"), list(results.values()), ex_list)

    def on_signal(signum, frame):
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, on_signal)
    count = max(1, min(opts.jobs, len(todo)))  # no more workers than submissions to grade
    workers = Workers(opts.work or os.path.join(opts.out, "work"), count)
    try:
        p0 = time.monotonic()
        if todo and any(not s.get("error") for s in todo):
            prime(workers, count, opts, key)
        t0, done, failed_build = time.monotonic(), 0, 0
        priming = t0 - p0
        with ThreadPoolExecutor(count) as pool:
            futures = {pool.submit(grade_one, s, workers, opts): s for s in todo}
            try:
                for fut in as_completed(futures):
                    r = fut.result()
                    with lock:
                        results[r["student"]] = r
                        done += 1
                        failed_build += r["build"] != "ok"
                        save()
                    left = len(todo) - done
                    eta = (time.monotonic() - t0) / done * left if done else 0
                    say(f"{done}/{len(todo)} graded, {failed_build} failed to build or to grade, "
                        f"{left} remaining, ETA {eta / 60:.1f} min: {r['student']} "
                        f"{r.get('total', 0)} points ({r['build']}, {r.get('seconds', 0):.0f} s)")
            except KeyboardInterrupt:
                for f in futures:
                    f.cancel()
                sandbox.stop_all()  # the graders' threads end with their sandboxed commands
                raise
    except KeyboardInterrupt:
        sandbox.stop_all()
        say(f"interrupted: {len(results)} results kept in {cache_path}; run the same command to go on")
        return 130
    finally:
        workers.close()
    save()
    with open(os.path.join(opts.out, "run.json"), "w") as f:
        json.dump({"jobs": opts.jobs, "graded": len(todo), "kept": len(subs) - len(todo),
                   "priming_seconds": round(priming, 2),
                   "grading_seconds": round(time.monotonic() - t0, 2)}, f, indent=1)
    write_summary(opts.out, [results[s["student"]] for s in subs], ex_list)
    say(f"done in {time.monotonic() - started:.0f} s: {opts.out}/class.csv, {opts.out}/index.html")
    return 0


def main(argv):
    p = argparse.ArgumentParser(prog="./workbook grade-class", description=__doc__.split("\n\n")[0],
                                epilog="\n\n".join(__doc__.split("\n\n")[2:]),
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("submissions", help="folder with one folder, git repository or archive per student")
    p.add_argument("--out", default=os.path.join(ROOT, "build", "class-grades"),
                   help="where the results go (default build/class-grades)")
    p.add_argument("--jobs", type=integer(1, MAX_JOBS), default=usable_cpus(),
                   help="students graded at once (default: the cores this process may use)")
    p.add_argument("--hidden", help="folder of extra doctest files stepNN*.cpp (as for grade)")
    p.add_argument("--steps", type=step_list, help="grade only these steps, e.g. 01,03")
    p.add_argument("--timeout", type=decimal(0, MAX_SECONDS), default=60.0, help="seconds per test case (default 60)")
    p.add_argument("--student-timeout", type=decimal(0, MAX_SECONDS), default=1800.0,
                   help="seconds for one student's whole grading (default 1800)")
    p.add_argument("--work", help="folder of the workers' grading folders (default OUT/work)")
    p.add_argument("--no-cache", action="store_true", help="grade every submission again")
    p.add_argument("--no-sandbox", action="store_true", help="run the tests without bubblewrap")
    opts = p.parse_args(argv)
    if not os.path.isdir(opts.submissions):
        p.error(f"{opts.submissions}: no such folder")
    return grade_class(opts)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
