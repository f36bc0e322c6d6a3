#!/usr/bin/python3
"""End-to-end tests of grading a class and of the platforms (ctest label "grading").

usage: tests/class_grading_test.py SCENARIO WORK_DIR
  class       a generated class of 6 (the first step with exercises only) graded with 2 jobs,
              stopped after the first results and resumed, scores exactly the expected points;
              a third run keeps every result, and a changed submission alone is graded again
  gradescope  the autograder bundle's run_autograder, in a simulated /autograder, gives the
              reference full points and the starter kit zero on every exercise, in
              Gradescope's results.json format
  classroom   the kit's GitHub Classroom workflow is valid YAML with one step per exercise
              worth its points, and its per-exercise command passes for the reference and
              fails for the kit

The scenarios share the grading folders in WORK_DIR/workers (ctest runs them one at a time):
the first one primes them, the others rebuild only the sources they change.
"""
import csv
import json
import os
import shutil
import signal
import subprocess
import sys
import time
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)  # the tools package, imported from the repository root
from tools.grading.class_bench import check as check_expected, make_class, student_sources  # noqa: E402
from tools.grading.classroom import CLASSROOM_STEP_TIMEOUT, exercise_command, step_id  # noqa: E402
from tools.grading.exercises import exercises, step_sources  # noqa: E402
from tools.grading.gradescope import isolation_works  # noqa: E402
from tools.grading.kit import CLASSROOM_WORKFLOW, write_kit  # noqa: E402

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
    for rel, text in files.items():
        os.makedirs(os.path.dirname(os.path.join(sub, rel)), exist_ok=True)
        with open(os.path.join(sub, rel), "w", encoding="utf-8") as f:
            f.write(text)
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
    check("workbook/tools/deps.sh\" build grade" in setup, "setup.sh installs the packages with tools/deps.sh")
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


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    scenario, work = sys.argv[1], os.path.abspath(sys.argv[2])
    os.makedirs(work, exist_ok=True)
    started = time.monotonic()
    {"class": scenario_class, "gradescope": scenario_gradescope, "classroom": scenario_classroom}[scenario](work)
    print(f"{scenario}: {time.monotonic() - started:.0f} s")
    print(f"{len(failures)} failed" if failures else "all checks passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
