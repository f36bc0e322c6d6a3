"""Writes a starter kit: a copy of the workbook's tracked files (git ls-files; no build
output) with every solution block replaced by a stub that throws NotImplemented("N.M").
The grader (GRADER below, and its tests) stays out of the kit: it needs the solutions.

usage: ./workbook kit DIR [--no-pictures]   (python3 -m tools.grading.kit DIR, from the root)

The kit also gets the reference pictures of `./workbook check` (tools/pictures.py renders
them with this tree's programs, the solutions): pictures and numbers, never code.

Nothing between the markers survives: the kit's file is the reference file with each
block's lines (from BEGIN SOLUTION to END SOLUTION, both included) replaced by the stub, and
the tool checks that before it finishes. The stub also names the function's parameters as
(void) casts, so the kit compiles without unused-parameter warnings.
"""
import os
import shutil
import subprocess
import sys

from . import ROOT
from .classroom import workflow
from .exercises import BEGIN, END, SOURCE_SUFFIXES, exercises, parse_file

SKIP_DIRS = {".git", "build", "out", "kit", "node_modules", "__pycache__"}
# The grader's modules: they belong to the instructor's reference tree (they need the
# solutions). Their end-to-end tests and unit tests stay out with them.
GRADER = ("grade", "grade_report", "grading_tree", "box", "build_and_run", "errors", "grade_class",
          "gradescope", "class_bench", "mutants", "safeguards", "judge", "mutant_generator",
          "differential")
NOT_IN_KIT = ({f"tools/grading/{m}.py" for m in GRADER} | {f"tests/tools/test_{m}.py" for m in GRADER}
              | {"tests/grading_test.py", "tests/judge_test.py", "tests/class_grading_test.py", "tests/box_test.py",
                 "tests/check_test.py", "tests/lab_test.py"}
              # The attempts behind the measured figures: the kit's pages state results.
              | {"docs/trials.md"})
# The catalogues of students' mistakes and of the hard cases' safeguards
# (tools/grading/mutants.py, safeguards.py): patches of the solutions; and the judge (the
# grader's checker and worker harness).
NOT_IN_KIT_DIRS = ("tests/mutants/", "tests/safeguards/", "tools/grading/judge/")


def in_kit(rel):
    """Whether the tree's file `rel` (relative, with /) goes into the kit as it is or stubbed."""
    return rel not in NOT_IN_KIT and not rel.startswith(NOT_IN_KIT_DIRS)
CLASSROOM_WORKFLOW = ".github/workflows/classroom.yml"  # GitHub Classroom (classroom.py)


def tracked_files(root):
    """The tree's files that git tracks or would track (not ignored build output), or,
    outside git, every file but build output."""
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z", "--cached", "--others",
                              "--exclude-standard"], check=True,
                             capture_output=True, text=True).stdout
        files = [f for f in out.split("\0") if f and os.path.isfile(os.path.join(root, f))]
        if files:
            return files
    except (OSError, subprocess.CalledProcessError):
        pass
    files = []
    for base, dirs, names in os.walk(root):
        dirs[:] = [d for d in dirs if d not in SKIP_DIRS]
        files += [os.path.relpath(os.path.join(base, n), root) for n in names]
    return sorted(files)


def stub_lines(ex, indent):
    """The lines that replace one solution block."""
    lines = [f"{indent}// TODO: your solution (see the step's README)"]
    if ex.parameters:
        lines.append(indent + " ".join(f"(void){p};" for p in ex.parameters))
    lines.append(f'{indent}throw NotImplemented("{ex.id}");')
    return lines


def strip_solutions(text, path, root, keep=()):
    """The file's text with every solution block replaced (but those of the exercises in
    `keep`, e.g. {"1.4"}); returns (new text, the exercises replaced)."""
    lines = text.split("\n")
    found = [e for e in parse_file(path, root) if e.id not in keep]
    for ex in found:
        if ex.begin < 0 or ex.end < 0:
            raise SystemExit(f"kit: {ex.path}: exercise {ex.id} has no complete "
                             "BEGIN SOLUTION ... END SOLUTION block (is this tree a starter kit "
                             "already? kits and grading start from the reference tree)")
    for ex in sorted(found, key=lambda e: -e.begin):
        indent = lines[ex.begin][: len(lines[ex.begin]) - len(lines[ex.begin].lstrip())]
        lines[ex.begin : ex.end + 1] = stub_lines(ex, indent)
    new = "\n".join(lines)
    if found and "core/exercise.hpp" not in new:
        # NotImplemented lives there; put the include after the file's first include.
        at = next((i for i, l in enumerate(lines) if l.startswith("#include")), -1)
        lines.insert(at + 1, '#include "core/exercise.hpp"')
        new = "\n".join(lines)
    return new, found


def check_no_solution_left(reference, kit):
    """Every line between markers in the reference is gone from the kit's file, unless
    the same line also stands outside every block in the reference."""
    ref_lines = reference.split("\n")
    inside, outside, in_block = set(), set(), False
    for line in ref_lines:
        if BEGIN.match(line):
            in_block = True
            continue
        if END.match(line):
            in_block = False
            continue
        (inside if in_block else outside).add(line.strip())
    kit_lines = {l.strip() for l in kit.split("\n")}
    leaked = [l for l in inside if l and l not in outside and l in kit_lines]
    if any(BEGIN.match(l) or END.match(l) for l in kit.split("\n")):
        leaked.append("a BEGIN/END SOLUTION marker")
    return leaked


def write_kit(dest, root=ROOT):
    if os.path.abspath(dest) == os.path.abspath(root):
        raise SystemExit("kit: the kit must go into another folder than the workbook itself")
    if os.path.exists(dest) and os.listdir(dest):
        raise SystemExit(f"kit: {dest} exists and is not empty; choose a new folder")
    stubbed = []
    for rel in tracked_files(root):
        if not in_kit(rel):
            continue
        src, dst = os.path.join(root, rel), os.path.join(dest, rel)
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        if rel.startswith("steps/") and rel.endswith(SOURCE_SUFFIXES):
            with open(src, encoding="utf-8") as f:
                text = f.read()
            new, found = strip_solutions(text, src, root)
            leaked = check_no_solution_left(text, new)
            if leaked:
                raise SystemExit(f"kit: {rel}: solution text would survive: {leaked[0]!r}")
            with open(dst, "w", encoding="utf-8") as f:
                f.write(new)
            shutil.copymode(src, dst)
            stubbed += found
        else:
            shutil.copy2(src, dst)
    # GitHub Classroom's autograding: one step per exercise with its points.
    os.makedirs(os.path.dirname(os.path.join(dest, CLASSROOM_WORKFLOW)), exist_ok=True)
    with open(os.path.join(dest, CLASSROOM_WORKFLOW), "w", encoding="utf-8") as f:
        f.write(workflow(exercises(root)))
    return stubbed


def main(argv):
    pictures = "--no-pictures" not in argv
    args = [a for a in argv if a != "--no-pictures"]
    if len(args) != 1 or args[0].startswith("-"):
        print("usage: ./workbook kit DIR [--no-pictures]   (writes the starter kit into the new "
              "folder DIR)", file=sys.stderr)
        return 2
    stubbed = write_kit(args[0])
    points = sum(e.points for e in stubbed)
    print(f"[workbook] starter kit in {args[0]}: {len(stubbed)} exercises ({points} points) "
          "replaced by stubs that throw NotImplemented", file=sys.stderr)
    for e in sorted(stubbed, key=lambda e: e.key):
        print(f"  {e.id:>5}  {e.points} pt  {e.path}  {e.title}", file=sys.stderr)
    if pictures:
        from ..pictures import render_references  # noqa: PLC0415

        render_references(args[0], ROOT, log=lambda t: print(t, file=sys.stderr))
    print(f"[workbook] the student's loop in it: cd {args[0]} && ./workbook check", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
