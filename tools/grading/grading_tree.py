"""The grading tree in WORK/src: the reference's files, the starter kit's stubs of the step
sources, the student's step sources over them and the judge's workers (a call server per
step). No hidden test is ever in it: those live in the judge's folder (tools/grading/judge)."""
import os
import re

from . import ROOT
from .errors import GradeError
from .exercises import SOURCE_SUFFIXES, step_dirs
from .grade_report import printable
from .kit import strip_solutions, tracked_files
from .submissions import SubmissionError, read_tree


def read(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return f.read()


def student_sources(student, step_names, notes):
    """{relative path: text} of the student's sources in the reference's step folders, read
    as the submission reader reads a folder (submissions.read_tree): regular files only,
    never through a link, within its limits. What it refused, and why, goes into `notes`."""
    refused = []
    try:
        files = read_tree(student, refused)
    except SubmissionError as e:
        raise GradeError(printable(f"grade: {student}: {e}")) from None
    notes += refused
    return {rel: data.decode("utf-8", errors="replace") for rel, data in files.items()
            if rel.split("/")[1] in step_names}


def hidden_tests(hidden, step_numbers):
    """{step number: [file names]} of an instructor's hidden test files (stepNN*.cpp)."""
    by_step = {}
    if not hidden:
        return by_step
    if not os.path.isdir(hidden):
        raise GradeError(f"grade: --hidden {hidden}: no such folder")
    for f in sorted(os.listdir(hidden)):
        m = re.match(r"(?:test_)?step(\d\d)", f)
        if not f.endswith(".cpp"):
            continue
        if not m or m.group(1) not in step_numbers:
            raise GradeError(f"grade: hidden test {f}: name it stepNN*.cpp for one of the steps "
                             f"{', '.join(sorted(step_numbers))}")
        by_step.setdefault(m.group(1), []).append(f)
    return by_step


def sync_tree(dest, files):
    """Makes dest hold exactly `files` ({relative path: bytes}); unchanged files keep their
    time stamps, so the build dir rebuilds only what changed."""
    for rel, data in files.items():
        path = os.path.join(dest, rel)
        try:
            with open(path, "rb") as f:
                if f.read() == data:
                    continue
        except OSError:
            pass
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "wb") as f:
            f.write(data)
    wanted = {os.path.normpath(r) for r in files}
    for d, _, names in os.walk(dest, topdown=False):
        for n in names:
            rel = os.path.normpath(os.path.relpath(os.path.join(d, n), dest))
            if rel not in wanted:
                os.remove(os.path.join(d, n))
        if d != dest and not os.listdir(d):
            os.rmdir(d)


def hidden_sources(hidden, step_numbers, steps):
    """{step: [(file name, bytes)]} of the instructor's hidden tests of the graded steps."""
    by_step = {}
    for number, names in hidden_tests(hidden, step_numbers).items():
        if number in steps:
            for n in names:
                with open(os.path.join(hidden, n), "rb") as f:
                    by_step.setdefault(number, []).append((n, f.read()))
    return by_step


def assemble(student, work, extra=None, cmake=""):
    """Writes the grading tree into work/src; returns the notes for the report. `extra`
    ({relative path: bytes}) and `cmake` (lines for the top CMakeLists.txt): the judge's
    workers (judge.worker_files)."""
    notes = []
    step_names = [os.path.basename(d) for d in step_dirs(ROOT)]
    files = {}
    for rel in tracked_files(ROOT):
        path = os.path.join(ROOT, rel)
        if rel.startswith("steps/") and rel.endswith(SOURCE_SUFFIXES):
            text, _ = strip_solutions(read(path), path, ROOT)  # the kit's stub
            files[rel] = text.encode()
        else:
            with open(path, "rb") as f:
                files[rel] = f.read()
    owned = student_sources(student, step_names, notes)
    if not owned:
        notes.append(f"no step sources found under {student}/steps: every exercise is a stub")
    for rel, text in owned.items():
        if rel not in files and rel.endswith((".cpp", ".cc")):
            notes.append(f"{rel} is new: it is not built (the reference CMake files list the sources)")
        files[rel] = text.encode()
    files.update(extra or {})
    if cmake:
        files["CMakeLists.txt"] += cmake.encode()
    sync_tree(os.path.join(work, "src"), files)
    return notes


def share_tree(src):
    """The grading tree readable to everyone (the compilers run as the student user; root's
    umask may be 077)."""
    os.chmod(src, 0o755)
    for d, dirs, files in os.walk(src):
        for n in dirs:
            os.chmod(os.path.join(d, n), 0o755)
        for n in files:
            path = os.path.join(d, n)
            if not os.path.islink(path):
                os.chmod(path, 0o755 if os.stat(path).st_mode & 0o100 else 0o644)
