"""GitHub Classroom: the starter kit's autograding workflow (.github/workflows/classroom.yml).

usage: python3 -m tools.grading.classroom [--steps 01,02]    prints the workflow (kit.py writes it)
       python3 -m tools.grading.classroom --run N.M [TREE]   runs one exercise's command as the
                                                              workflow does

One grading step per exercise, each with the exercise's points as its max-score, so a
student gets partial credit per exercise. The steps use GitHub Classroom's actions:
classroom-resources/autograding-command-grader (a command; its exit status decides) and
classroom-resources/autograding-grading-reporter (the points to Classroom). The rule is the
grader's (grade.py): the kit's tests are built once (`cmake --build -k 0`, so a step
that does not compile costs only its own exercises), then the exercise's command runs every
test case of its doctest suite "exercise N.M" as its own process with a time limit
(`ctest -L '^exercise N\\.M$'`, each case a ctest test); the exercise earns its points when
there is at least one case and all pass. Unlike grade.py, the tests run from the
student's own repository, so a student can change them: the instructor's grade of record
comes from grade.py, grade_class.py or the Gradescope bundle.
"""
import subprocess
import sys

from . import ROOT
from .exercises import exercises

CASE_TIMEOUT = 60  # seconds per test case, as grade.py's default
CLASSROOM_STEP_TIMEOUT = 10  # minutes for one exercise's step (the action's unit)


def step_id(ex_id):
    return "exercise-" + ex_id.replace(".", "-")


def exercise_command(ex_id, build_dir="build/release"):
    """The shell command that passes when every test case of exercise N.M passes."""
    label = "^exercise " + ex_id.replace(".", r"\.") + "$"
    return (f"ctest --test-dir {build_dir} -L '{label}' --no-tests=error "
            f"--timeout {CASE_TIMEOUT} --output-on-failure")


def quote(text):
    """A YAML double-quoted scalar."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def workflow(all_ex):
    lines = [
        "# Autograding for GitHub Classroom: one step per exercise, each worth its points.",
        "# Written by the workbook's tools/grading/classroom.py (see docs/instructors.md).",
        "name: Autograding Tests",
        "'on': [push, workflow_dispatch, repository_dispatch]",
        "permissions:",
        "  checks: write",
        "  actions: read",
        "  contents: read",
        "jobs:",
        "  run-autograding-tests:",
        "    runs-on: ubuntu-24.04",
        "    if: github.actor != 'github-classroom[bot]'",
        "    steps:",
        "    - name: Checkout code",
        "      uses: actions/checkout@v4",
        "    - name: Install the packages (tools/deps.sh)",
        "      run: sudo apt-get update && sudo tools/deps.sh build test",
        "    - name: Build the tests (a step that does not compile costs only its exercises)",
        "      run: cmake --preset release && (cmake --build --preset release -- -k 0 || true)",
    ]
    for e in all_ex:
        lines += [
            f"    - name: {quote(f'exercise {e.id}: {e.title} ({e.points} point' + 's' * (e.points != 1) + ')')}",
            f"      id: {step_id(e.id)}",
            "      uses: classroom-resources/autograding-command-grader@v1",
            "      with:",
            f"        test-name: {quote(f'exercise {e.id}: {e.title}')}",
            f"        command: {quote(exercise_command(e.id))}",
            f"        timeout: {CLASSROOM_STEP_TIMEOUT}",
            f"        max-score: {e.points}",
        ]
    lines += [
        "    - name: Autograding Reporter",
        "      uses: classroom-resources/autograding-grading-reporter@v1",
        "      env:",
    ]
    for e in all_ex:
        sid = step_id(e.id)
        lines.append(f"        {sid.upper()}_RESULTS: \"${{{{steps.{sid}.outputs.result}}}}\"")
    lines += ["      with:", f"        runners: {','.join(step_id(e.id) for e in all_ex)}", ""]
    return "\n".join(lines)


def main(argv):
    if argv[:1] == ["--run"] and len(argv) in (2, 3):
        tree = argv[2] if len(argv) == 3 else "."
        return subprocess.run(exercise_command(argv[1]), shell=True, cwd=tree).returncode
    all_ex = exercises(ROOT)
    if argv[:1] == ["--steps"] and len(argv) == 2:
        steps = [s.zfill(2) for s in argv[1].split(",")]
        all_ex = [e for e in all_ex if f"{e.step:02d}" in steps]
    elif argv:
        print(__doc__, file=sys.stderr)
        return 2
    sys.stdout.write(workflow(all_ex))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
