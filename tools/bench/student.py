"""The student's time: how long the workbook's own commands make a student wait, measured
as a student meets them, in a fresh kit and a fresh clone.

usage: ./workbook bench student [--rows kit,edit,watch,exam,hang,tour,test] [--repeat N]
                                [--edits N] [--rev REV] [--keep] [--json FILE]
       (python3 -m tools.bench.student ..., from the tree's root; in a clone or a kit)

Rows (the targets are the workbook's promises to a student on a 2-core machine):
  kit    a fresh kit, `./workbook check` (next: exercise 1.1): until 1.1's verdict is on
         screen; cold (no compiler cache, no build folder), then warm (a fresh build
         folder, the compiler cache of the cold run)
  edit   a one-line edit in exercise 2.3's file, `./workbook check 2.3`: until its verdict
         is on screen (--edits edits, the first check's build not counted)
  watch  `./workbook check 2.3 --watch`: from the save to the new verdict on screen
  exam   a fresh clone, `./workbook exam`: until the first question is on screen; cold, warm
  hang   exercise 1.1 that never returns, `./workbook check 1.1`: until its verdict is on
         screen, and until the command ends (no picture is rendered for it)
  tour   a fresh clone, `./workbook tour`: its build part (until step 01 renders); cold
  test   a fresh clone, `./workbook test`: the whole run (the packages installed before)

Cold runs point CCACHE_DIR at an empty folder of their own (the warm run after them reuses
it); nothing reads the user's compiler cache. "A fresh clone" is `git clone` of this tree
(its last commit; --rev REV: that commit), or in a kit a copy of the kit. The fresh kit
is written from that clone by tools/grading/kit.py (without pictures), or is that copy.
Each row is the median of --repeat runs (edit and watch: of --edits edits); the table gives
the target, the median, met or missed and by how much, the runs, and the load average
before and after the row. Everything runs under build/bench-student/ (removed unless --keep).
"""
import argparse
import json
import os
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time

from tools import ROOT
from tools.grading.kit import tracked_files

# (row, what the student does, target seconds)
TARGETS = [
    ("kit", "fresh kit, `./workbook check` (next 1.1): first verdict, cold", 60),
    ("kit-warm", "the same with a warm compiler cache", None),
    ("edit", "one-line edit, `./workbook check 2.3`: verdict (median of edits)", 2.0),
    ("edit-done", "the same, until the command ends (pictures made)", None),
    ("watch", "`--watch`: save to verdict (median of edits)", 2.5),
    ("exam", "fresh clone, `./workbook exam`: first question, cold", 30),
    ("exam-warm", "the same with a warm compiler cache", None),
    ("hang", "exercise that never returns: its verdict", 15),
    ("hang-done", "the same, until the command ends", None),
    ("tour", "fresh clone, `./workbook tour`: the build part, cold", 180),
    ("test", "fresh clone, `./workbook test`: the whole run", 300),
]
ROWS = ("kit", "edit", "watch", "exam", "hang", "tour", "test")
EXERCISE_FILE_MARK = "EXERCISE 2.3:"


def load():
    return os.getloadavg()[0]


class Session:
    """A command whose output lines are timed as they come (stdout and stderr together)."""

    def __init__(self, cmd, cwd, env, stdin=None):
        self.started = time.monotonic()
        self.lines = []
        self.cond = threading.Condition()
        self.p = subprocess.Popen(cmd, cwd=cwd, env=env, stdin=stdin or subprocess.DEVNULL,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                  errors="replace", start_new_session=True)
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.p.stdout:
            with self.cond:
                self.lines.append((time.monotonic(), line.rstrip("\n")))
                self.cond.notify_all()
        with self.cond:
            self.cond.notify_all()

    def wait_for(self, pattern, after=0, timeout=3600):
        """(time, index) of the first line from `after` on that matches, or (None, n)."""
        deadline = time.monotonic() + timeout
        with self.cond:
            while True:
                for i in range(after, len(self.lines)):
                    if re.search(pattern, self.lines[i][1]):
                        return self.lines[i][0], i
                left = deadline - time.monotonic()
                if left <= 0 or (self.p.poll() is not None and self.p.stdout.closed):
                    return None, len(self.lines)
                self.cond.wait(min(left, 0.5))

    def finish(self, timeout=3600):
        """Waits for the end; the seconds since the start."""
        try:
            self.p.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.stop()
        return time.monotonic() - self.started

    def stop(self):
        if self.p.poll() is None:
            try:
                os.killpg(self.p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        self.p.wait()

    def text(self):
        return "\n".join(l for _, l in self.lines)


def env_with(cache_dir=None):
    env = dict(os.environ)
    if cache_dir:
        os.makedirs(cache_dir, exist_ok=True)
        env["CCACHE_DIR"] = cache_dir
    return env


def fresh_clone(source, dest, rev=None):
    """A fresh clone of the tree (git), or in a kit a copy of its files."""
    if os.path.isdir(os.path.join(source, ".git")) or os.path.isfile(os.path.join(source, ".git")):
        subprocess.run(["git", "clone", "--quiet", "--no-hardlinks", source, dest], check=True)
        if rev:
            subprocess.run(["git", "-C", dest, "checkout", "--quiet", rev], check=True)
        return dest
    for rel in tracked_files(source):
        os.makedirs(os.path.dirname(os.path.join(dest, rel)), exist_ok=True)
        shutil.copy2(os.path.join(source, rel), os.path.join(dest, rel))
    return dest


def is_kit(tree):
    return not os.path.isfile(os.path.join(tree, "tools", "grading", "grade.py"))


def fresh_kit(clone, dest):
    """A starter kit written from the clone (or the clone itself when it is a kit)."""
    if is_kit(clone):
        shutil.copytree(clone, dest, symlinks=True, ignore=shutil.ignore_patterns("build", "out"))
        return dest
    subprocess.run([sys.executable, "-m", "tools.grading.kit", dest, "--no-pictures"], cwd=clone,
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return dest


def verdict_pattern(exercise):
    """A row of check's table for the exercise: its verdict on screen."""
    return rf"^\s+{re.escape(exercise)}\s+\d+/\d+\s+\S"


def exercise_file(tree, exercise):
    for base, _, names in os.walk(os.path.join(tree, "steps")):
        for n in names:
            if n.endswith((".cpp", ".hpp")):
                path = os.path.join(base, n)
                with open(path, encoding="utf-8") as f:
                    if f"EXERCISE {exercise}:" in f.read():
                        return path
    raise SystemExit(f"bench student: no file holds exercise {exercise}")


def one_line_edit(path, k):
    """A one-line code edit of the file: a new unused constant at its end (a new object
    file, the same behaviour); the line of the edit before replaced."""
    with open(path, encoding="utf-8") as f:
        text = re.sub(r"\n\[\[maybe_unused\]\] static const int kBenchEdit = \d+;\n", "\n", f.read())
    with open(path, "w", encoding="utf-8") as f:
        f.write(text + f"\n[[maybe_unused]] static const int kBenchEdit = {k};\n")


# The rows ------------------------------------------------------------------------------------


def row_kit(work, clone, repeat, log, warm_too=True):
    """Cold and warm: a fresh kit each time, `./workbook check` until 1.1's verdict."""
    cold, warm = [], []
    for i in range(repeat):
        cache = os.path.join(work, f"ccache-kit-{i}")
        for kind, runs in (("cold", cold), ("warm", warm))[: 2 if warm_too else 1]:
            kit = fresh_kit(clone, os.path.join(work, f"kit-{kind}-{i}"))
            s = Session(["./workbook", "check"], kit, env_with(cache))
            t, _ = s.wait_for(verdict_pattern("1.1"), timeout=3600)
            s.stop()
            log(f"kit {kind} {i + 1}/{repeat}", s)
            runs.append(None if t is None else t - s.started)
            shutil.rmtree(kit, ignore_errors=True)
        shutil.rmtree(cache, ignore_errors=True)
    return {"kit": cold, "kit-warm": warm}


def warm_kit(work, clone, log):
    """A kit with exercise 2.3 and step 01 built (the compiler cache warm), for the edits."""
    kit = os.path.join(work, "kit-edits")
    if not os.path.isdir(kit):
        fresh_kit(clone, kit)
        for which in ("2.3", "1.1"):
            s = Session(["./workbook", "check", which], kit, env_with(os.path.join(work, "ccache-edits")))
            s.finish()
            log(f"warming the kit: check {which}", s)
    return kit


def row_edit(work, clone, edits, log):
    kit = warm_kit(work, clone, log)
    path = exercise_file(kit, "2.3")
    verdict, done = [], []
    for k in range(edits):
        one_line_edit(path, k + int(time.time()))
        s = Session(["./workbook", "check", "2.3"], kit, env_with(os.path.join(work, "ccache-edits")))
        t, _ = s.wait_for(verdict_pattern("2.3"))
        end = s.finish()
        log(f"edit {k + 1}/{edits}", s)
        verdict.append(None if t is None else t - s.started)
        done.append(end)
    return {"edit": verdict, "edit-done": done}


def row_watch(work, clone, edits, log):
    kit = warm_kit(work, clone, log)
    path = exercise_file(kit, "2.3")
    s = Session(["./workbook", "check", "2.3", "--watch"], kit, env_with(os.path.join(work, "ccache-edits")))
    times = []
    try:
        _, i = s.wait_for(r"^\[check\] watching steps/", timeout=1800)
        for k in range(edits):
            time.sleep(1.3)  # a save a moment after the run
            saved = time.monotonic()
            one_line_edit(path, k + int(time.time()))
            _, j = s.wait_for(r"changed: checking again", i + 1, timeout=60)
            t, _ = s.wait_for(verdict_pattern("2.3"), j, timeout=600)
            times.append(None if t is None else t - saved)
            _, i = s.wait_for(r"^\[check\] watching steps/", j, timeout=600)
    finally:
        s.stop()
        log("watch", s)
    return {"watch": times}


def row_exam(work, clone, repeat, log, warm_too=True):
    cold, warm = [], []
    for i in range(repeat):
        cache = os.path.join(work, f"ccache-exam-{i}")
        for kind, runs in (("cold", cold), ("warm", warm))[: 2 if warm_too else 1]:
            shutil.rmtree(os.path.join(clone, "build"), ignore_errors=True)
            s = Session(["./workbook", "exam"], clone, env_with(cache), stdin=subprocess.PIPE)
            t, _ = s.wait_for(r"^== Question 1 of", timeout=3600)
            s.stop()
            log(f"exam {kind} {i + 1}/{repeat}", s)
            runs.append(None if t is None else t - s.started)
        shutil.rmtree(cache, ignore_errors=True)
    shutil.rmtree(os.path.join(clone, "build"), ignore_errors=True)
    return {"exam": cold, "exam-warm": warm}


def row_hang(work, clone, repeat, log):
    kit = warm_kit(work, clone, log)
    path = exercise_file(kit, "1.1")
    with open(path, encoding="utf-8") as f:
        original = f.read()
    # The stub's throw replaced by a loop that never ends (a volatile read each turn: no
    # compiler may remove it).
    hanging = re.sub(r'throw NotImplemented\("1\.1"\);',
                     "for (volatile int spin = 0;; spin = spin + 0) {\n    }", original, count=1)
    if hanging == original:
        raise SystemExit("bench student: exercise 1.1's stub was not found (is it solved?)")
    verdict, done = [], []
    try:
        with open(path, "w", encoding="utf-8") as f:
            f.write(hanging)
        for i in range(repeat):
            s = Session(["./workbook", "check", "1.1"], kit, env_with(os.path.join(work, "ccache-edits")))
            t, _ = s.wait_for(verdict_pattern("1.1"))
            end = s.finish()
            log(f"hang {i + 1}/{repeat}", s)
            verdict.append(None if t is None or "timed out" not in s.text() else t - s.started)
            done.append(end)
    finally:
        with open(path, "w", encoding="utf-8") as f:
            f.write(original)
    return {"hang": verdict, "hang-done": done}


def row_tour(work, clone, repeat, log):
    runs = []
    for i in range(repeat):
        shutil.rmtree(os.path.join(clone, "build"), ignore_errors=True)
        shutil.rmtree(os.path.join(clone, "out"), ignore_errors=True)
        s = Session(["./workbook", "tour"], clone, env_with(os.path.join(work, f"ccache-tour-{i}")))
        t, _ = s.wait_for(r"step \d\d_\w+: rendering", timeout=7200)
        s.stop()
        log(f"tour {i + 1}/{repeat}", s)
        runs.append(None if t is None else t - s.started)
        shutil.rmtree(os.path.join(work, f"ccache-tour-{i}"), ignore_errors=True)
    return {"tour": runs}


def row_test(work, clone, repeat, log):
    runs = []
    for i in range(repeat):
        shutil.rmtree(os.path.join(clone, "build"), ignore_errors=True)
        s = Session(["./workbook", "test"], clone, env_with(os.path.join(work, f"ccache-test-{i}")))
        end = s.finish(timeout=7200)
        log(f"test {i + 1}/{repeat} (exit {s.p.returncode})", s)
        runs.append(end if s.p.returncode == 0 else None)
        shutil.rmtree(os.path.join(work, f"ccache-test-{i}"), ignore_errors=True)
    return {"test": runs}


# The table -----------------------------------------------------------------------------------


def seconds(x):
    return "-" if x is None else f"{x:.1f} s" if x < 100 else f"{x:.0f} s"


def table(results, loads):
    head = ("what the student does", "target", "measured (median)", "verdict", "runs (s)", "load")
    rows = []
    for key, what, target in TARGETS:
        if key not in results:
            continue
        runs = results[key]
        if not runs:
            continue
        ok = [r for r in runs if r is not None]
        median = statistics.median(ok) if ok and len(ok) == len(runs) else None
        if median is None:
            verdict = "failed to measure" if runs else "-"
        elif target is None:
            verdict = ""
        elif median <= target:
            verdict = f"met ({target - median:.1f} s to spare)"
        else:
            verdict = f"MISSED by {median - target:.1f} s ({median / target:.1f}x)"
        before, after = loads.get(key.split("-")[0], (None, None))
        rows.append((what, f"<= {target:g} s" if target else "", seconds(median), verdict,
                     " ".join("x" if r is None else f"{r:.1f}" for r in runs),
                     "" if before is None else f"{before:.1f} -> {after:.1f}"))
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join(" --- " for _ in head) + "|"]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)


def main(argv):
    p = argparse.ArgumentParser(prog="./workbook bench student", description=__doc__.split("\n")[0])
    p.add_argument("--rows", default=",".join(ROWS), help="which rows (default: all)")
    p.add_argument("--repeat", type=int, default=None,
                   help="runs per row (default: kit, exam, hang 3; tour, test 1)")
    p.add_argument("--edits", type=int, default=5, help="edits for the edit and watch rows")
    p.add_argument("--no-warm", action="store_true", help="the cold runs only (kit, exam)")
    p.add_argument("--rev", help="clone this commit instead of the last one")
    p.add_argument("--keep", action="store_true", help="keep build/bench-student/")
    p.add_argument("--json", help="also write the runs as JSON here")
    opts = p.parse_args(argv)
    rows = [r for r in opts.rows.split(",") if r]
    for r in rows:
        if r not in ROWS:
            p.error(f"no row '{r}' (rows: {', '.join(ROWS)})")
    base = os.path.join(ROOT, "build")
    os.makedirs(base, exist_ok=True)
    work = tempfile.mkdtemp(prefix="bench-student-", dir=base)
    logfile = open(os.path.join(work, "log.txt"), "w", encoding="utf-8")

    def log(title, session):
        logfile.write(f"\n==== {title}: {time.monotonic() - session.started:.1f} s\n{session.text()}\n")
        logfile.flush()
        print(f"[bench] {title}: {time.monotonic() - session.started:.1f} s (load {load():.1f})",
              file=sys.stderr, flush=True)

    started_load = load()
    results, loads = {}, {}
    try:
        clone = fresh_clone(ROOT, os.path.join(work, "clone"), opts.rev)
        for r in rows:
            before = load()
            n = opts.repeat or (1 if r in ("tour", "test") else 3)
            if r == "kit":
                results.update(row_kit(work, clone, n, log, not opts.no_warm))
            elif r == "edit":
                results.update(row_edit(work, clone, opts.edits, log))
            elif r == "watch":
                results.update(row_watch(work, clone, opts.edits, log))
            elif r == "exam":
                results.update(row_exam(work, clone, n, log, not opts.no_warm))
            elif r == "hang":
                results.update(row_hang(work, clone, n, log))
            elif r == "tour":
                results.update(row_tour(work, clone, n, log))
            elif r == "test":
                results.update(row_test(work, clone, n, log))
            loads[r] = (before, load())
    finally:
        logfile.close()
        print(f"[bench] the commands' output: {os.path.relpath(os.path.join(work, 'log.txt'), ROOT)}"
              if opts.keep else "", file=sys.stderr)
    commit = subprocess.run(["git", "-C", os.path.join(work, "clone"), "log", "-1", "--format=%h %s"],
                            capture_output=True, text=True).stdout.strip()[:80] or "a kit"
    print(f"The student's time ({commit}; {os.cpu_count()} cores, load average "
          f"{started_load:.1f} at the start, {load():.1f} at the end)\n")
    print(table(results, loads))
    if opts.json:
        with open(opts.json, "w", encoding="utf-8") as f:
            json.dump({"commit": commit, "results": results, "loads": loads}, f, indent=1)
    if not opts.keep:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
