"""A generated class for the class grader: its test data and its benchmark.

usage: python3 -m tools.grading.class_bench make DEST [--students N] [--steps 01] [--seed S]
       python3 -m tools.grading.class_bench check OUT EXPECTED.json
       python3 -m tools.grading.class_bench bench [--students 30] [--steps 01] [--jobs 1,2]
                                                  [--out DIR]
       (./workbook bench-grading ... is the bench; run from the repository root)

make: DEST/submissions/ gets N submissions (N >= 6), copies of the starter kit with
varying exercises of the graded steps solved (their reference solution blocks kept, the
others stubs, as kit.py writes them): one with nothing solved, one with everything,
one whose step does not compile, one whose solved exercise loops forever, one whose solved
exercise crashes (SIGSEGV), the rest random subsets. They come as folders, git
repositories, .zip (with a top folder) and .tar.gz archives. DEST/expected.json holds the
points each must get per exercise: what its solved exercises are worth, nothing for a step
that does not compile or an exercise that loops or crashes.

check: compares OUT/cache.json of a class grading with the expected points, exactly.

bench: makes a class (default 30 students, step 01 only, so one student costs the compile of
one step's sources and its test cases), primes the grading folders, grades it with 1 and
with 2 jobs (--jobs) and prints the seconds per submission, the speed-up and whether every
result is exact.
"""
import argparse
import json
import os
import random
import re
import shutil
import subprocess
import sys
import tarfile
import zipfile

from . import ROOT, grade_class
from .strict_numbers import MAX_JOBS, MAX_SECONDS, decimal, integer, integer_list, step_list
from .exercises import exercises, step_sources
from .kit import strip_solutions, write_kit

LOOP = "for (volatile unsigned spin = 0; spin != 1u; spin = spin + 2u) {}  // never ends"
CRASH = "std::raise(SIGSEGV);  // a crash"


def cases_per_exercise():
    """{exercise id: number of TEST_CASEs in its suites} from the reference tests."""
    counts = {}
    for base, _, names in os.walk(os.path.join(ROOT, "tests")):
        for name in names:
            if name.endswith(".cpp"):
                counts_in(os.path.join(base, name), counts)
    return counts


def counts_in(path, counts):
    """Adds the TEST_CASEs per exercise suite of one test file to counts."""
    with open(path, encoding="utf-8") as f:
        parts = re.split(r'TEST_SUITE\("', f.read())
    for p in parts[1:]:
        m = re.match(r"exercise (\d+\.\d+)\"", p)
        if m:
            counts[m.group(1)] = counts.get(m.group(1), 0) + len(re.findall(r"\bTEST_CASE\(", p))


def insert_into_block(text, ex_id, line, include=None):
    """Puts `line` first in the (kept) solution block of exercise ex_id."""
    lines = text.split("\n")
    at = next(i for i, l in enumerate(lines) if re.search(rf"//\s*EXERCISE\s+{re.escape(ex_id)}:", l))
    begin = next(i for i in range(at, len(lines)) if "BEGIN SOLUTION" in lines[i])
    indent = lines[begin][: len(lines[begin]) - len(lines[begin].lstrip())]
    lines.insert(begin + 1, indent + line)
    if include:
        first = next(i for i, l in enumerate(lines) if l.startswith("#include"))
        lines.insert(first + 1, include)
    return "\n".join(lines)


def student_sources(solved, sabotage=None):
    """{relative path: text} of the step sources with `solved` kept; sabotage is
    (kind, exercise id) with kind "loop", "crash" or "syntax"."""
    files = {}
    for path in step_sources(ROOT):
        rel = os.path.relpath(path, ROOT)
        with open(path, encoding="utf-8") as f:
            text, _ = strip_solutions(f.read(), path, ROOT, keep=set(solved))
        files[rel] = text
    if sabotage:
        kind, ex_id = sabotage
        rel = next(e.path for e in exercises(ROOT) if e.id == ex_id)
        if kind == "loop":
            files[rel] = insert_into_block(files[rel], ex_id, LOOP)
        elif kind == "crash":
            files[rel] = insert_into_block(files[rel], ex_id, CRASH, "#include <csignal>")
        else:
            files[rel] += "\nthis line is not C++;\n"
    return files


def write_tree(kit, dest, files):
    shutil.copytree(kit, dest, symlinks=True)
    for rel, text in files.items():
        with open(os.path.join(dest, rel), "w", encoding="utf-8") as f:
            f.write(text)


def make_class(dest, count=30, steps=("01",), seed=1):
    """Writes DEST/submissions and DEST/expected.json; returns the expected points
    {student: {exercise: points}}."""
    if count < 6:
        raise SystemExit("class_bench: at least 6 students (the special cases take 5)")
    all_ex = exercises(ROOT)
    graded = [e for e in all_ex if f"{e.step:02d}" in steps]
    if not graded:
        raise SystemExit(f"class_bench: no exercises in steps {','.join(steps)}")
    ids = [e.id for e in graded]
    points = {e.id: e.points for e in graded}
    by_cases = sorted(ids, key=lambda i: (cases_per_exercise().get(i, 99), i))
    looping, crashing = by_cases[0], by_cases[1] if len(by_cases) > 1 else by_cases[0]
    broken_step = f"{graded[0].step:02d}"
    rng = random.Random(seed)
    plan = [("s00-nothing", [], None), ("s01-everything", ids, None),
            ("s02-no-compile", ids, ("syntax", graded[0].id)),
            ("s03-loops", ids, ("loop", looping)), ("s04-crashes", ids, ("crash", crashing))]
    for i in range(len(plan), count):
        plan.append((f"s{i:02d}-random", sorted(rng.sample(ids, rng.randint(1, len(ids) - 1)),
                                                 key=lambda x: tuple(map(int, x.split(".")))), None))
    if os.path.exists(dest):
        shutil.rmtree(dest)
    subs = os.path.join(dest, "submissions")
    os.makedirs(subs)
    kit = os.path.join(dest, "kit")
    write_kit(kit, ROOT)
    expected = {}
    for n, (name, solved, sabotage) in enumerate(plan):
        files = student_sources(solved, sabotage)
        got = {i: (points[i] if i in solved else 0) for i in ids}
        if sabotage and sabotage[0] == "syntax":
            got.update({i: 0 for i in ids if i.split(".")[0].zfill(2) == broken_step})
        elif sabotage:
            got[sabotage[1]] = 0
        expected[name] = got
        form = n % 4  # folders, git repositories, zip and tar.gz archives in turn
        if form == 0:
            write_tree(kit, os.path.join(subs, name), files)
        elif form == 1:
            repo = os.path.join(subs, name)
            write_tree(kit, repo, files)
            git = ["git", "-C", repo, "-c", "user.name=student", "-c", "user.email=student@example.org"]
            subprocess.run(git + ["init", "-q"], check=True)
            subprocess.run(git + ["add", "-A"], check=True)
            subprocess.run(git + ["commit", "-q", "-m", "my work"], check=True)
        else:
            tmp = os.path.join(dest, "tmp", name)
            write_tree(kit, tmp, files)
            if form == 2:  # a zip with a top folder, as "compress folder" makes it
                with zipfile.ZipFile(os.path.join(subs, name + ".zip"), "w", zipfile.ZIP_DEFLATED) as z:
                    for base, _, names in os.walk(tmp):
                        for f in names:
                            full = os.path.join(base, f)
                            z.write(full, os.path.join(name, os.path.relpath(full, tmp)))
            else:
                with tarfile.open(os.path.join(subs, name + ".tar.gz"), "w:gz") as t:
                    for entry in sorted(os.listdir(tmp)):
                        t.add(os.path.join(tmp, entry), entry)
    shutil.rmtree(os.path.join(dest, "tmp"), ignore_errors=True)
    shutil.rmtree(kit)
    with open(os.path.join(dest, "expected.json"), "w") as f:
        json.dump(expected, f, indent=1)
    return expected


def check(out, expected_path):
    """[(student, problem)] where the class grading differs from the expected points."""
    with open(expected_path) as f:
        expected = json.load(f)
    with open(os.path.join(out, "cache.json")) as f:
        results = json.load(f)["results"]
    wrong = []
    for student, want in sorted(expected.items()):
        r = None
        for key in (student, student + ".zip", student + ".tar.gz"):
            r = r or results.get(key)
        if not r:
            wrong.append((student, "no result"))
            continue
        got = {row["exercise"]: row["points"] for row in r["rows"]}
        diff = [f"{i}: {got.get(i)} instead of {p}" for i, p in want.items() if got.get(i) != p]
        if diff:
            wrong.append((student, "; ".join(diff)))
    return wrong


def run_class(subs, out, work, jobs, steps, timeout):
    """The class grader, in-process, as ./workbook grade-class runs it."""
    code = grade_class.main([subs, "--out", out, "--work", work, "--jobs", str(jobs),
                             "--steps", ",".join(steps), "--timeout", f"{timeout:g}", "--no-cache"])
    if code != 0:
        raise SystemExit(f"class_bench: grade_class exited {code}")
    with open(os.path.join(out, "run.json")) as f:
        return json.load(f)


def bench(args):
    out = os.path.abspath(args.out)
    steps = args.steps
    print(f"[bench-grading] a class of {args.students} in {out}/class (steps {','.join(steps)})",
          file=sys.stderr)
    make_class(os.path.join(out, "class"), args.students, steps, args.seed)
    jobs_list = args.jobs
    work = os.path.abspath(args.work) if args.work else os.path.join(out, "work")
    rows = []
    for jobs in jobs_list:
        run = run_class(os.path.join(out, "class", "submissions"), os.path.join(out, f"jobs{jobs}"),
                        work, jobs, steps, args.timeout)
        wrong = check(os.path.join(out, f"jobs{jobs}"), os.path.join(out, "class", "expected.json"))
        rows.append((jobs, run, wrong))
    load = os.getloadavg()[0]
    print(f"\nGrading a generated class of {args.students} submissions (steps {','.join(steps)}; "
          f"{os.cpu_count()} cores; load average {load:.1f} at the end)\n")
    print(f"{'jobs':>4} {'seconds':>8} {'s/submission':>13} {'speed-up':>9} {'priming s':>10}  exact")
    base = rows[0][1]["grading_seconds"]
    for jobs, run, wrong in rows:
        s = run["grading_seconds"]
        print(f"{jobs:>4} {s:>8.1f} {s / run['graded']:>13.2f} {base / s:>9.2f} "
              f"{run['priming_seconds']:>10.1f}  "
              f"{'yes' if not wrong else f'NO: {len(wrong)} wrong'}")
    failures = [(j, w) for j, _, w in rows if w]
    for jobs, wrong in failures:
        for student, problem in wrong:
            print(f"  jobs {jobs}: {student}: {problem}")
    print("\nPriming (once per grading folder) builds the core and the reference's tests; "
          "after it, a submission costs the compile of its step sources, the relink and its test cases.")
    return 1 if failures else 0


def main(argv):
    p = argparse.ArgumentParser(prog="python3 -m tools.grading.class_bench", description=__doc__.split("\n\n")[0],
                                epilog="\n\n".join(__doc__.split("\n\n")[1:]),
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    m = sub.add_parser("make")
    m.add_argument("dest")
    m.add_argument("--students", type=integer(1, 10000), default=30)
    m.add_argument("--steps", type=step_list, default="01")
    m.add_argument("--seed", type=integer(0, 2**63 - 1), default=1)
    c = sub.add_parser("check")
    c.add_argument("out")
    c.add_argument("expected")
    b = sub.add_parser("bench")
    b.add_argument("--students", type=integer(1, 10000), default=30)
    b.add_argument("--steps", type=step_list, default="01")
    b.add_argument("--seed", type=integer(0, 2**63 - 1), default=1)
    b.add_argument("--jobs", type=integer_list(1, MAX_JOBS), default="1,2")
    b.add_argument("--timeout", type=decimal(0, MAX_SECONDS), default=10.0, help="seconds per test case (default 10)")
    b.add_argument("--out", default=os.path.join(ROOT, "build", "bench-grading"))
    b.add_argument("--work", help="the grading folders (default OUT/work; kept between runs)")
    args = p.parse_args(argv)
    if args.command == "make":
        expected = make_class(args.dest, args.students, args.steps, args.seed)
        print(f"[class] {len(expected)} submissions in {args.dest}/submissions, expected points in "
              f"{args.dest}/expected.json", file=sys.stderr)
        return 0
    if args.command == "check":
        wrong = check(args.out, args.expected)
        for student, problem in wrong:
            print(f"WRONG {student}: {problem}")
        print("every student has the expected points" if not wrong else f"{len(wrong)} students wrong")
        return 1 if wrong else 0
    return bench(args)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
