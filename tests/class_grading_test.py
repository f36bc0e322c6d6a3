#!/usr/bin/python3
"""End-to-end tests of grading a class and of the platforms (ctest label "grading").

usage: python3 -m tests.class_grading_test SCENARIO WORK_DIR
  class       a generated class of 6 (the first step with exercises only) graded with 2 jobs,
              stopped after the first results and resumed, scores exactly the expected points;
              a third run keeps every result, and a changed submission alone is graded again
  gradescope  the autograder bundle's run_autograder, in a simulated /autograder, gives the
              reference full points and the starter kit zero on every exercise, in
              Gradescope's results.json format
  classroom   the kit's GitHub Classroom workflow is valid YAML with one step per exercise
              worth its points, and its per-exercise command passes for the reference and
              fails for the kit
  gradescope-setup, gradescope-read, gradescope-results, gradescope-daemon, gradescope-fork,
  gradescope-control, gradescope-cleanup
              Gradescope as it is: the bundle (with a hidden test) run as root where
              bubblewrap cannot run (a fake one that fails), its setup.sh creating the
              unprivileged user (a name of this work folder's own; cleanup removes it). setup
              gives the reference full points; then hostile submissions, each a correct step
              but for one exercise: it reads the solutions and the hidden tests, rewrites
              results.json from a setsid daemon, leaves a daemon holding its output, forks
              without end, prints control characters. Each ends with the right points, an
              intact results.json with no solution or hidden text, and no process of the user
              left (skipped, 77, when not root: creating users needs it)

The scenarios share the grading folders in WORK_DIR/workers (ctest runs them one at a time):
the first one primes them, the others rebuild only the sources they change.
"""
import csv
import hashlib
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
import zipfile

from tools import ROOT
from tools.grading.class_bench import check as check_expected, make_class, student_sources
from tools.grading.classroom import CLASSROOM_STEP_TIMEOUT, exercise_command, step_id
from tools.grading.exercises import exercises, step_sources
from tools.grading.grade import solution_files
from tools.grading.kit import CLASSROOM_WORKFLOW, write_kit
from tools.grading.sandbox import isolation_problem
from tools.grading.submissions import write_files
from tools.grading.users import processes_of

SKIPPED = 77  # ctest's SKIP_RETURN_CODE


def isolation_works():
    return isolation_problem() is None

failures = []
TIMEOUT = "10"  # seconds per test case: the looping student costs it once per case


def check(condition, message):
    print(("ok    " if condition else "FAIL  ") + message, flush=True)
    if not condition:
        failures.append(message)


def first_step():
    return sorted({f"{e.step:02d}" for e in exercises(ROOT)})[0]


def no_isolation():
    """Where bubblewrap cannot run (some containers), the tests run without it, on purpose."""
    if isolation_works():
        return []
    print("note: bubblewrap cannot run here: grading without isolation")
    return ["--no-isolation"]


def tool(module):
    """A grading tool as ./workbook runs it: a module of the tools package, from the root."""
    return [sys.executable, "-m", f"tools.grading.{module}"]


def class_cmd(subs, out, work, jobs=2):
    return tool("grade_class") + [subs, "--out", out, "--work", work, "--jobs", str(jobs),
                                  "--steps", first_step(), "--timeout", TIMEOUT] + \
        (["--no-sandbox"] if no_isolation() else [])


def table(out):
    """class.csv without the seconds column."""
    with open(os.path.join(out, "class.csv")) as f:
        return [row[:-1] for row in csv.reader(f)]


def scenario_class(work):
    dest = os.path.join(work, "class")
    expected = make_class(dest, 6, [first_step()])
    subs, out, workers = os.path.join(dest, "submissions"), os.path.join(work, "class-out"), os.path.join(work, "workers")
    shutil.rmtree(out, ignore_errors=True)
    # Run 1: stopped (SIGTERM, as a Ctrl-C) once the first results are in.
    p = subprocess.Popen(class_cmd(subs, out, workers), stderr=subprocess.PIPE, text=True, cwd=ROOT)
    stopped = False
    for line in p.stderr:
        sys.stdout.write(line)
        if "1/6 graded" in line:
            p.send_signal(signal.SIGTERM)
            stopped = True
    p.wait()
    check(stopped and p.returncode == 130, f"the first run stops after its first result (exit {p.returncode})")
    with open(os.path.join(out, "cache.json")) as f:
        kept = len(json.load(f)["results"])
    check(1 <= kept < 6, f"the stopped run kept {kept} results")
    # Run 2: goes on without grading those again.
    r = subprocess.run(class_cmd(subs, out, workers), capture_output=True, text=True, cwd=ROOT)
    print(r.stderr)
    check(r.returncode == 0, "the resumed run finishes")
    with open(os.path.join(out, "run.json")) as f:
        run = json.load(f)
    check(run["kept"] == kept and run["graded"] == 6 - kept,
          f"the resumed run keeps the {kept} results and grades the other {6 - kept}: {run}")
    wrong = check_expected(out, os.path.join(dest, "expected.json"))
    for student, problem in wrong:
        print(f"  {student}: {problem}")
    check(not wrong, "every student has exactly the points of the exercises that work")
    rows = table(out)
    ids = [e.id for e in exercises(ROOT) if f"{e.step:02d}" == first_step()]
    check(rows[0][: len(ids) + 1] == ["student"] + ids and len(rows) == 7, "class.csv: a row per student")
    by_student = {row[0]: row for row in rows[1:]}
    for student, points in expected.items():
        got = by_student.get(student, [])
        check(got[1 : len(ids) + 2] == [str(points[i]) for i in ids] + [str(sum(points.values()))],
              f"class.csv: {student} {got[1:]}")
    broken = by_student.get("s02-no-compile", [""])
    check("does not compile" in broken[-1], f"class.csv: the build status says so: {broken[-1]}")
    for student in expected:
        report = os.path.join(out, "students", student)
        check(os.path.exists(os.path.join(report, "grade.xml")) and
              "Grade:" in open(os.path.join(report, "points.txt")).read(), f"{student}: a report")
    page = open(os.path.join(out, "index.html")).read()
    check("points.png" in page and "most common first failure" in page and "is not implemented yet" in page,
          "index.html: the distribution and the most common failures")
    # Run 3: nothing changed, nothing graded; then one changed submission alone is graded.
    r = subprocess.run(class_cmd(subs, out, workers), capture_output=True, text=True, cwd=ROOT)
    run = json.load(open(os.path.join(out, "run.json")))
    check(r.returncode == 0 and run["graded"] == 0 and table(out) == rows, f"an unchanged class keeps its table: {run}")
    changed = os.path.join(subs, "s00-nothing")
    solved = ids[0]
    for rel, text in student_sources([solved]).items():
        with open(os.path.join(changed, rel), "w", encoding="utf-8") as f:
            f.write(text)
    r = subprocess.run(class_cmd(subs, out, workers), capture_output=True, text=True, cwd=ROOT)
    run = json.load(open(os.path.join(out, "run.json")))
    got = {row[0]: row for row in table(out)[1:]}["s00-nothing"]
    points = {e.id: e.points for e in exercises(ROOT)}
    check(run["graded"] == 1 and got[len(ids) + 1] == str(points[solved]),
          f"a changed submission alone is graded again: {run}, {got}")


def gradescope_run(work, root, files):
    sub = os.path.join(root, "submission")
    shutil.rmtree(sub, ignore_errors=True)
    write_files(sub, files)
    results = os.path.join(root, "results", "results.json")
    if os.path.exists(results):
        os.remove(results)
    env = dict(os.environ, AUTOGRADER_ROOT=root, BOXES_GRADE_WORK=os.path.join(work, "workers", "w0"))
    # Gradescope copies run_autograder to /autograder and runs it from there.
    r = subprocess.run([os.path.join(root, "run_autograder")], cwd=root, env=env, capture_output=True, text=True)
    print(r.stdout[-1500:], r.stderr[-1500:])
    check(r.returncode == 0, "run_autograder exits 0")
    with open(results) as f:
        return json.load(f)


def check_format(doc, label):
    """The fields of Gradescope's documented results.json (gradescope-autograders.readthedocs.io
    specs): tests with name, score, max_score, status passed/failed, output, visibility."""
    ok = isinstance(doc.get("tests"), list) and isinstance(doc.get("score"), (int, float))
    for t in doc.get("tests", []):
        ok = ok and isinstance(t.get("name"), str) and isinstance(t.get("score"), (int, float))
        ok = ok and isinstance(t.get("max_score"), (int, float)) and t.get("status") in ("passed", "failed")
        ok = ok and isinstance(t.get("output"), str)
        ok = ok and t.get("visibility") in ("hidden", "after_due_date", "after_published", "visible")
        ok = ok and set(t) <= {"score", "max_score", "status", "name", "name_format", "number", "output",
                               "output_format", "tags", "visibility", "extra_data"}
    ok = ok and set(doc) <= {"score", "execution_time", "output", "output_format", "test_output_format",
                             "test_name_format", "visibility", "stdout_visibility", "extra_data", "tests",
                             "leaderboard"}
    check(ok, f"{label}: results.json has Gradescope's fields")


def scenario_gradescope(work):
    step = first_step()
    ids = {e.id: e.points for e in exercises(ROOT) if f"{e.step:02d}" == step}
    bundle = os.path.join(work, "autograder.zip")
    r = subprocess.run(tool("gradescope") + ["bundle", bundle, "--steps", step, "--timeout", "30"],
                       capture_output=True, text=True, cwd=ROOT)
    check(r.returncode == 0, "the bundle is written")
    root = os.path.join(work, "autograder")
    shutil.rmtree(root, ignore_errors=True)
    with zipfile.ZipFile(bundle) as z:
        names = z.namelist()
        check({"setup.sh", "run_autograder", "workbook/tools/grading/grade.py", "workbook/tools/deps.sh"} <= set(names),
              "the bundle has setup.sh and run_autograder at its root, and the grader")
        for info in z.infolist():  # zipfile does not restore the modes
            z.extract(info, os.path.join(root, "source"))
            mode = (info.external_attr >> 16) & 0o777
            if mode:
                os.chmod(os.path.join(root, "source", info.filename), mode)
    setup = open(os.path.join(root, "source", "setup.sh")).read()
    check("workbook/tools/deps.sh\" grade" in setup, "setup.sh installs the packages with tools/deps.sh grade")
    shutil.copy2(os.path.join(root, "source", "run_autograder"), os.path.join(root, "run_autograder"))

    reference = {os.path.relpath(p, ROOT): open(p, encoding="utf-8").read()
                 for p in step_sources(ROOT)}
    doc = gradescope_run(work, root, reference)
    check_format(doc, "reference")
    tests = {t["number"]: t for t in doc.get("tests", [])}
    check(sorted(tests) == sorted(ids), f"reference: one test per exercise of step {step}")
    check(all(tests[i]["score"] == ids[i] == tests[i]["max_score"] and tests[i]["status"] == "passed"
              for i in ids if i in tests), "reference: every exercise has full points")
    check(doc.get("score") == sum(ids.values()), f"reference: score {doc.get('score')} of {sum(ids.values())}")

    doc = gradescope_run(work, root, student_sources([]))
    check_format(doc, "kit")
    tests = {t["number"]: t for t in doc.get("tests", [])}
    check(sorted(tests) == sorted(ids) and all(tests[i]["score"] == 0 and tests[i]["status"] == "failed"
                                               and "not implemented" in tests[i]["output"] for i in ids),
          "kit: zero on every exercise, the output naming the missing exercise")
    check(doc.get("score") == 0, "kit: score 0")


def scenario_classroom(work):
    import yaml  # python3-yaml (tools/deps.sh test)

    kit = os.path.join(work, "kit-classroom")
    shutil.rmtree(kit, ignore_errors=True)
    write_kit(kit, ROOT)
    with open(os.path.join(kit, CLASSROOM_WORKFLOW)) as f:
        doc = yaml.safe_load(f)
    steps = doc["jobs"]["run-autograding-tests"]["steps"]
    graders = [s for s in steps if s.get("uses", "").startswith("classroom-resources/autograding-command-grader@")]
    all_ex = exercises(ROOT)
    check([g["id"] for g in graders] == [step_id(e.id) for e in all_ex], "one grading step per exercise")
    check(all(g["with"]["max-score"] == e.points and g["with"]["command"] == exercise_command(e.id)
              and 0 < g["with"]["timeout"] <= CLASSROOM_STEP_TIMEOUT for g, e in zip(graders, all_ex)),
          "each step is worth its exercise's points and runs its command")
    reporter = steps[-1]
    check(reporter.get("uses", "").startswith("classroom-resources/autograding-grading-reporter@")
          and reporter["with"]["runners"].split(",") == [g["id"] for g in graders]
          and all(reporter["env"][f"{g['id'].upper()}_RESULTS"] == f"${{{{steps.{g['id']}.outputs.result}}}}"
                  for g in graders), "the reporter collects every step's result")
    check(set(doc["on"]) >= {"push"} and doc["permissions"]["checks"] == "write", "runs on push with checks: write")
    # The per-exercise commands, in a grading build of the first step (the reference's tests
    # with the kit's sources, then with the reference's): fail for the kit, pass when solved.
    step = first_step()
    w0 = os.path.join(work, "workers", "w0")
    for tree, label, want in ((kit, "kit", 1), (ROOT, "reference", 0)):
        r = subprocess.run(tool("grade") + [tree, "--work", w0, "--steps", step, "--timeout", "30",
                                            "--junit", os.path.join(work, "classroom.xml")] + no_isolation(),
                           capture_output=True, text=True, cwd=ROOT)
        check(r.returncode == 0, f"{label}: graded into the shared grading build")
        # The grader configures its tree without ctest discovery (BOXES_GRADING); the kit's
        # workflow runs ctest in an ordinary build, so turn discovery back on for this step.
        build = os.path.join(w0, "build")
        c = subprocess.run(f"cmake -S {w0}/src -B {build} -DBOXES_GRADING=OFF >/dev/null && "
                           f"cmake --build {build} --target test_step{step} >/dev/null",
                           shell=True, capture_output=True, text=True)
        check(c.returncode == 0, f"{label}: the step's tests discovered for ctest ({c.stderr.strip()[-300:]})")
        for e in [e for e in all_ex if f"{e.step:02d}" == step]:
            cmd = exercise_command(e.id, os.path.join(w0, "build"))
            c = subprocess.run(cmd, shell=True, capture_output=True, text=True)
            check((c.returncode != 0) == bool(want) and "tests passed" in c.stdout,
                  f"{label}: the command of exercise {e.id} {'fails' if want else 'passes'} ({c.stdout.strip().splitlines()[-1:]})")


# Gradescope as it is: root, no bubblewrap, hostile submissions -----------------------------

HIDDEN_TOKEN = "hidden-source-token-5d1c"  # in the hidden test's source only


def grading_user(work):
    """A user name of this work folder's own: test runs in other trees do not share it."""
    return "boxes-t" + hashlib.sha1(os.path.abspath(work).encode()).hexdigest()[:8]


def user_processes(name):
    """The pids of the processes whose real or effective user is `name` (zombies aside)."""
    try:
        uid = int(subprocess.run(["id", "-u", name], capture_output=True, text=True, check=True).stdout)
    except (subprocess.CalledProcessError, ValueError):
        return []
    return [pid for pid, _ in processes_of(uid)]


def layout_root(work):
    return os.path.join(work, "gradescope-root")


def root_env(work, root):
    """The environment of setup.sh and run_autograder here: bubblewrap unusable (a fake that
    fails, as in Docker), the user of this work folder, the shared grading folder."""
    fake = os.path.join(work, "fake-bwrap")
    with open(fake, "w") as f:
        f.write("#!/bin/sh\necho 'bwrap: No permissions to create new namespace' >&2\nexit 1\n")
    os.chmod(fake, 0o755)
    return dict(os.environ, AUTOGRADER_ROOT=root, BOXES_GRADE_WORK=os.path.join(work, "workers", "w0"),
                BOXES_BWRAP=fake, BOXES_GRADING_USER=grading_user(work), BOXES_SKIP_APT="1")


def step_ids():
    return [e.id for e in exercises(ROOT) if f"{e.step:02d}" == first_step()]


def secret_lines():
    """Lines of the solution blocks (long enough to be telling): none may reach a student."""
    lines = set()
    for rel in solution_files():
        inside = False
        for line in open(os.path.join(ROOT, rel), encoding="utf-8"):
            if "BEGIN SOLUTION" in line:
                inside = True
            elif "END SOLUTION" in line:
                inside = False
            elif inside and len(line.strip()) > 25:
                lines.add(line.strip())
    return lines


def scenario_gradescope_setup(work):
    if os.geteuid() != 0:
        print("SKIP: creating the grading user needs root")
        return SKIPPED
    root = layout_root(work)
    shutil.rmtree(root, ignore_errors=True)
    hidden = os.path.join(work, "gradescope-hidden")
    shutil.rmtree(hidden, ignore_errors=True)
    os.makedirs(hidden)
    first = step_ids()[0]
    with open(os.path.join(hidden, f"step{first_step()}_extra.cpp"), "w") as f:
        f.write(f'#include <doctest/doctest.h>\n// {HIDDEN_TOKEN}: the instructor\'s own words\n'
                f'TEST_SUITE("exercise {first}") {{\n    TEST_CASE("hidden: one more check") {{ CHECK(1 + 1 == 2); }}\n}}\n')
    bundle = os.path.join(work, "autograder-hidden.zip")
    r = subprocess.run(tool("gradescope") + ["bundle", bundle, "--steps", first_step(), "--timeout", "20",
                                             "--limit", "400", "--hidden", hidden], capture_output=True, text=True, cwd=ROOT)
    check(r.returncode == 0, f"the bundle with a hidden test is written ({r.stderr.strip()[-300:]})")
    with zipfile.ZipFile(bundle) as z:
        for info in z.infolist():
            z.extract(info, os.path.join(root, "source"))
            mode = (info.external_attr >> 16) & 0o777
            if mode:
                os.chmod(os.path.join(root, "source", info.filename), mode)
    shutil.copy2(os.path.join(root, "source", "run_autograder"), os.path.join(root, "run_autograder"))
    env = root_env(work, root)
    subprocess.run(["userdel", env["BOXES_GRADING_USER"]], capture_output=True)
    r = subprocess.run([os.path.join(root, "source", "setup.sh")], env=env, capture_output=True, text=True)
    print(r.stdout[-1500:], r.stderr[-2500:])
    check(r.returncode == 0, "setup.sh, as root without bubblewrap, primes the grading build")
    check(f"student code as user {env['BOXES_GRADING_USER']}" in r.stderr, "setup.sh: the students' code runs as the user it created")
    check(os.stat(os.path.join(root, "source")).st_mode & 0o077 == 0, "setup.sh: the bundle is the grader's only")
    doc = gradescope_root_run(work, {os.path.relpath(p, ROOT): open(p, encoding="utf-8").read()
                                     for p in step_sources(ROOT)}, "reference")
    tests = {t["number"]: t for t in doc.get("tests", [])}
    check(all(tests.get(i, {}).get("score") == tests.get(i, {}).get("max_score") for i in step_ids())
          and set(step_ids()) <= set(tests) and doc.get("score") == sum(t["max_score"] for t in tests.values()),
          "reference: full points as the user")
    check(tests.get(first, {}).get("visibility") == "after_published" and f"{first}.0" in tests
          and "hidden:" not in tests[f"{first}.0"]["output"],
          f"reference: exercise {first} with its hidden test is shown after publishing, its public tests now")
    check("also have hidden tests" in doc.get("output", "") and f"{doc.get('score')} of" not in doc.get("output", ""),
          f"reference: the top-level output gives no total with the hidden points: {doc.get('output', '')[:200]!r}")
    # results.json on every path: an overall time limit too short for the build (the kit
    # compiles its own sources), a grader that fails (a config it cannot read), and a
    # run_autograder whose Python does not start.
    config = os.path.join(root, "source", "config.json")
    saved = open(config).read()
    try:
        with open(config, "w") as f:
            json.dump(dict(json.loads(saved), limit=1), f)
        doc = gradescope_root_run(work, student_sources([]), "limit")
        check(doc.get("score") == 0 and len(doc.get("tests", [])) >= len(step_ids()) and all(
            "not graded: the grading ran past its overall time limit" in t["output"]
            for t in doc["tests"] if t["number"] in step_ids()), "limit: every exercise says it was not graded in time")
        with open(config, "w") as f:
            f.write("{ not json")
        doc = gradescope_root_run(work, student_sources([]), "grader failure")
        check(doc.get("score") == 0 and "not a verdict on your code" in doc.get("output", ""),
              f"grader failure: zero points and a message: {doc.get('output', '')[:120]!r}")
    finally:
        with open(config, "w") as f:
            f.write(saved)
    env = dict(root_env(work, root), PATH="/nonexistent")
    r = subprocess.run(["/bin/bash", os.path.join(root, "run_autograder")], cwd=root, env=env, capture_output=True, text=True)
    with open(os.path.join(root, "results", "results.json")) as f:
        doc = json.load(f)
    check(r.returncode == 0 and doc.get("score") == 0 and "failed before it could grade" in doc.get("output", ""),
          f"no Python: run_autograder still writes results.json: {doc.get('output', '')[:120]!r}")
    return None


def scenario_gradescope_cleanup(work):
    if os.geteuid() != 0:
        return SKIPPED
    name = grading_user(work)
    left = user_processes(name)
    check(not left, f"no process of {name} is left: {left}")
    r = subprocess.run(["userdel", name], capture_output=True, text=True)
    check(r.returncode == 0, f"the grading user {name} is removed ({r.stderr.strip()})")
    return None


def gradescope_root_run(work, files, label):
    """run_autograder as Gradescope runs it, here as root without bubblewrap: results.json,
    after the common checks (Gradescope's format, the results folder holds it alone, no
    solution or hidden text in it, no process of the user left)."""
    root = layout_root(work)
    sub = os.path.join(root, "submission")
    shutil.rmtree(sub, ignore_errors=True)
    write_files(sub, files)
    env = root_env(work, root)
    started = time.monotonic()
    r = subprocess.run([os.path.join(root, "run_autograder")], cwd=root, env=env, capture_output=True, text=True,
                       timeout=900)
    seconds = time.monotonic() - started
    print(r.stdout[-2000:], r.stderr[-3000:])
    check(r.returncode == 0, f"{label}: run_autograder exits 0 ({seconds:.0f} s)")
    time.sleep(0.5)  # what a daemon might still do after the grader ended
    results = os.path.join(root, "results")
    check(sorted(os.listdir(results)) == ["results.json"], f"{label}: the results folder holds results.json alone: "
          f"{sorted(os.listdir(results))}")
    with open(os.path.join(results, "results.json"), encoding="utf-8") as f:
        text = f.read()
    doc = json.loads(text)
    check_format(doc, label)
    leaked = [line for line in secret_lines() if line in text]
    check(not leaked and HIDDEN_TOKEN not in text, f"{label}: no solution line and no hidden test text in "
          f"results.json: {leaked[:2]}")
    check(not any(re.search("[\x00-\x08\x0b-\x1f\x7f\ufffe\uffff]", t) for t in strings(doc)),
          f"{label}: results.json holds no control characters")
    left = user_processes(env["BOXES_GRADING_USER"])
    check(not left, f"{label}: no process of the grading user is left: {left}")
    doc["_seconds"] = seconds
    return doc


def strings(doc):
    """Every string in a JSON document."""
    if isinstance(doc, str):
        yield doc
    elif isinstance(doc, dict):
        for k, v in doc.items():
            yield k
            yield from strings(v)
    elif isinstance(doc, list):
        for v in doc:
            yield from strings(v)


def hostile_files(body=None, static=None):
    """The reference's step sources; the last exercise of the first step gets `body` in place
    of its solution, its file `static` (code at namespace scope) at its end."""
    files = {os.path.relpath(p, ROOT): open(p, encoding="utf-8").read() for p in step_sources(ROOT)}
    target = [e for e in exercises(ROOT) if e.id == step_ids()[-1]][0]
    lines = files[target.path].split("\n")
    if body is not None:
        lines[target.begin + 1:target.end] = ["    " + line for line in body]
    if static is not None:
        lines += static
    files[target.path] = HOSTILE_HEADERS + "\n".join(lines)
    return files, target.id


HOSTILE_HEADERS = "".join(f"#include <{h}>\n" for h in (
    "sys/types.h", "sys/stat.h", "fcntl.h", "unistd.h", "cerrno", "csignal", "cstdio", "cstdlib", "cstring",
    "stdexcept", "string"))


def expect_points(doc, label, failing=None, reason=""):
    """Every exercise of the step full but `failing` (zero, its output naming `reason`)."""
    tests = {t["number"]: t for t in doc.get("tests", [])}
    for i in step_ids():
        t = tests.get(i, {})
        if i == failing:
            check(t.get("score") == 0 and reason in t.get("output", ""),
                  f"{label}: exercise {i} scores 0: {t.get('output', '')[:400]!r}")
        else:
            check(t.get("score") == t.get("max_score") and t.get("status") == "passed",
                  f"{label}: exercise {i} keeps its points ({t.get('output', '')[:200]!r})")
    full = sum(t["max_score"] for n, t in tests.items() if n != failing)
    check(doc.get("score") == full, f"{label}: score {doc.get('score')}, expected {full}")


def scenario_gradescope_read(work):
    """Reads the solutions (the bundle's reference tree), the hidden tests (the bundle's and
    the judge's copies) and the results, and throws what it found."""
    if os.geteuid() != 0:
        return SKIPPED
    root = layout_root(work)
    w0 = os.path.join(work, "workers", "w0")
    first = [e for e in exercises(ROOT) if f"{e.step:02d}" == first_step()][0]
    paths = [os.path.join(root, "source", "workbook", first.path),
             os.path.join(root, "source", "hidden", f"step{first_step()}_extra.cpp"),
             os.path.join(w0, "judge", "src", "tests", "hidden", f"step{first_step()}_0.cpp"),
             os.path.join(root, "source", "workbook", "tools", "grading", "grade.py"),
             os.path.join(root, "submission", first.path)]
    listing = ", ".join(json.dumps(p) for p in paths)
    files, hostile = hostile_files(body=[
        "std::string report;",
        f"for (const char* path : {{{listing}}}) {{",
        "    int fd = open(path, O_RDONLY);",
        "    char text[200] = {0};",
        "    if (fd >= 0 && read(fd, text, sizeof text - 1) >= 0) report += std::string(\"read \") + path + \": \" + text + \"; \";",
        "    else report += std::string(\"cannot read \") + path + \" (\" + std::strerror(errno) + \"); \";",
        "    if (fd >= 0) close(fd);",
        "}",
        "throw std::runtime_error(report);"])
    doc = gradescope_root_run(work, files, "read")
    expect_points(doc, "read", hostile, "cannot read")
    out = next((t["output"] for t in doc.get("tests", []) if t.get("number") == hostile), "")
    for p in paths:
        check(f"cannot read {p} (Permission denied)" in out, f"read: {os.path.relpath(p, work)} is out of reach")
    return None


def daemon_static(loop):
    """A global object whose constructor (it runs at every start of the test program) leaves
    a daemon: a double fork and setsid, so neither its parent's end nor its process group
    ends it; it ignores SIGTERM and SIGHUP and runs `loop`."""
    return ["namespace {",
            "struct Daemon {",
            "    Daemon() {",
            "        if (fork() != 0) return;",
            "        setsid();",
            "        if (fork() != 0) std::_Exit(0);",
            "        std::signal(SIGTERM, SIG_IGN);",
            "        std::signal(SIGHUP, SIG_IGN);"] + ["        " + line for line in loop] + [
            "        std::_Exit(0);",
            "    }",
            "} daemon;",
            "}  // namespace"]


def scenario_gradescope_results(work):
    """A correct step whose test program leaves a daemon that rewrites results.json (999
    points) and drops a file beside it, for a minute: after grading too, if it could."""
    if os.geteuid() != 0:
        return SKIPPED
    results = os.path.join(layout_root(work), "results")
    forged = json.dumps({"score": 999, "output": "forged", "tests": []})
    files, _ = hostile_files(static=daemon_static([
        "for (int i = 0; i < 1200; ++i) {",
        f"    if (std::FILE* f = std::fopen({json.dumps(os.path.join(results, 'results.json'))}, \"w\")) {{",
        f"        std::fputs({json.dumps(forged)}, f);",
        "        std::fclose(f);",
        "    }",
        f"    if (std::FILE* f = std::fopen({json.dumps(os.path.join(results, 'owned.txt'))}, \"w\")) std::fclose(f);",
        "    usleep(50000);",
        "}"]))
    doc = gradescope_root_run(work, files, "results")
    check(doc.get("score") != 999 and "forged" not in doc.get("output", ""), "results: results.json is the grader's")
    expect_points(doc, "results")
    time.sleep(2)
    with open(os.path.join(results, "results.json")) as f:
        check(json.load(f).get("score") == doc.get("score"), "results: results.json unchanged 2 s after grading")
    return None


def scenario_gradescope_daemon(work):
    """A correct step whose test program leaves a daemon that keeps its stdout and stderr
    and sleeps: the cases still end at once and pass, and the daemon is gone."""
    if os.geteuid() != 0:
        return SKIPPED
    files, _ = hostile_files(static=daemon_static(["for (;;) sleep(1);"]))
    doc = gradescope_root_run(work, files, "daemon")
    expect_points(doc, "daemon")
    check(all("time limit" not in t.get("output", "") for t in doc.get("tests", [])),
          "daemon: no case waited for the daemon until its time limit")
    return None


def scenario_gradescope_fork(work):
    """Forks without end (the children fork too) until the process limit refuses, then says
    how far it got."""
    if os.geteuid() != 0:
        return SKIPPED
    # A C++ body as a list of lines, as the read scenario's: other code, the same shape (what
    # the duplicates tool pairs them for).
    files, hostile = hostile_files(body=[
        "int forked = 0;",
        "for (;;) {",
        "    pid_t child = fork();",
        "    if (child == 0) for (;;) fork();",
        "    if (child < 0) break;",
        "    ++forked;",
        "}",
        "throw std::runtime_error(\"forked \" + std::to_string(forked) + \" processes, then: \" + std::strerror(errno));"])
    doc = gradescope_root_run(work, files, "fork")
    expect_points(doc, "fork", hostile, "processes, then: Resource temporarily unavailable")
    out = next((t["output"] for t in doc.get("tests", []) if t.get("number") == hostile), "")
    counts = [int(n) for n in re.findall(r"forked (\d+) processes", out)]
    check(counts and max(counts) <= 256, f"fork: the process limit held (forked {counts}, at most 256 at once)")
    return None


CONTROL = "\\x1b[31mred\\x1b[0m bell\\x07 nul-free \\x01\\x02 del\\x7f nonchar\\xef\\xbf\\xbe bad\\xff end"


def scenario_gradescope_control(work):
    """Prints control characters (and bytes that are no UTF-8) on stdout and stderr, then
    throws them: the exception's message is the reason the checker reports (what the worker
    prints reaches no result); then the same tree by ./workbook grade as that user, whose
    JUnit XML must parse."""
    if os.geteuid() != 0:
        return SKIPPED
    files, hostile = hostile_files(body=[
        f'std::fputs("{CONTROL}\\n", stdout);',
        f'std::fputs("{CONTROL}\\n", stderr);',
        "std::fflush(nullptr);",
        f'throw std::runtime_error("{CONTROL}");'])
    doc = gradescope_root_run(work, files, "control")
    expect_points(doc, "control", hostile, "threw")
    out = next((t["output"] for t in doc.get("tests", []) if t.get("number") == hostile), "")
    check("\\x1b[31mred" in out and "\\x07" in out, f"control: written out, not raw: {out[-300:]!r}")
    # The grader itself, in the bundle's tree (the one the user cannot read), with JUnit XML.
    root = layout_root(work)
    tree = os.path.join(work, "control-tree")
    shutil.rmtree(tree, ignore_errors=True)
    write_files(tree, files)
    os.chmod(tree, 0o700)
    junit, js = os.path.join(work, "control.xml"), os.path.join(work, "control.json")
    env = root_env(work, root)
    r = subprocess.run([sys.executable, "-m", "tools.grading.grade", tree, "--work", env["BOXES_GRADE_WORK"],
                        "--steps", first_step(), "--timeout", "20", "--junit", junit, "--json", js,
                        "--no-isolation", "--user", env["BOXES_GRADING_USER"]],
                       cwd=os.path.join(root, "source", "workbook"), env=env, capture_output=True, text=True)
    print(r.stdout[-1500:], r.stderr[-1500:])
    check(r.returncode == 0, "control: ./workbook grade --no-isolation --user grades it")
    try:
        failure = ET.parse(junit).getroot().find(f".//testcase[@classname='exercise {hostile}']/failure")
        check(failure is not None and "\\x1b[31mred" in failure.get("message", ""),
              "control: the JUnit XML is well-formed and says what was printed")
    except (ET.ParseError, OSError) as e:
        check(False, f"control: the JUnit XML does not parse: {e}")
    return None


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    scenario, work = sys.argv[1], os.path.abspath(sys.argv[2])
    os.makedirs(work, exist_ok=True)
    started = time.monotonic()
    scenarios = {"class": scenario_class, "gradescope": scenario_gradescope, "classroom": scenario_classroom,
                 "gradescope-setup": scenario_gradescope_setup, "gradescope-read": scenario_gradescope_read,
                 "gradescope-results": scenario_gradescope_results, "gradescope-daemon": scenario_gradescope_daemon,
                 "gradescope-fork": scenario_gradescope_fork, "gradescope-control": scenario_gradescope_control,
                 "gradescope-cleanup": scenario_gradescope_cleanup}
    if scenario not in scenarios:
        print(__doc__, file=sys.stderr)
        return 2
    if scenarios[scenario](work) == SKIPPED:
        return SKIPPED
    print(f"{scenario}: {time.monotonic() - started:.0f} s")
    print(f"{len(failures)} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
