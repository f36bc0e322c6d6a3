"""The grading tree in WORK/src: the reference's files, the starter kit's stubs of the step
sources, the student's step sources over them, and the instructor's hidden tests under
neutral names, kept unreadable except while they compile."""
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


HIDDEN_DIR = "tests/hidden"  # where the grading tree keeps the hidden tests


def hidden_copies(work, number=None):
    """The grading tree's copies of the hidden tests (of step `number`, or all)."""
    folder = os.path.join(work, "src", HIDDEN_DIR)
    if not os.path.isdir(folder):
        return []
    return [os.path.join(folder, n) for n in sorted(os.listdir(folder))
            if number is None or n.startswith(f"step{number}_")]


def set_hidden_mode(work, mode, number=None):
    """chmod the hidden tests' copies: 0 while student code runs or a student's own source
    compiles (not even their owner may read them then: bubblewrap's nobody is the grader
    outside), readable only while they compile themselves."""
    for path in hidden_copies(work, number):
        os.chmod(path, mode)


def assemble(student, hidden, work, steps):
    """Writes the grading tree into work/src; returns the notes for the report. The hidden
    tests' copies get neutral names (tests/hidden/stepNN_K.cpp: nothing in the tree says
    what the instructor called them) and are left unreadable (set_hidden_mode)."""
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
    # Hidden tests: compiled into their step's test program.
    by_step = hidden_tests(hidden, {n[:2] for n in step_names})
    extra = ["", "# Added by tools/grading/grade.py: the instructor's hidden tests."]
    for number, names in by_step.items():
        if number not in steps:
            continue
        copies = []
        for k, n in enumerate(names):
            with open(os.path.join(hidden, n), "rb") as f:
                files[f"{HIDDEN_DIR}/step{number}_{k}.cpp"] = f.read()
            copies.append(f"hidden/step{number}_{k}.cpp")
        sources = " ".join(copies)
        extra.append(f"if(TARGET test_step{number})\n    target_sources(test_step{number} PRIVATE {sources})\nendif()")
        notes.append(f"hidden tests for step {number}: {', '.join(names)}")
    if len(extra) > 2:
        files["tests/CMakeLists.txt"] += ("\n".join(extra) + "\n").encode()
    set_hidden_mode(work, 0o600)  # the grader compares and rewrites them
    sync_tree(os.path.join(work, "src"), files)
    set_hidden_mode(work, 0)
    return notes


def share_tree(src):
    """The grading tree readable to everyone (the compilers run as the student user; root's
    umask may be 077), but for the hidden tests (set_hidden_mode)."""
    os.chmod(src, 0o755)
    for d, dirs, files in os.walk(src):
        if os.path.relpath(d, src) == HIDDEN_DIR:
            continue
        for n in dirs:
            os.chmod(os.path.join(d, n), 0o755)
        for n in files:
            path = os.path.join(d, n)
            if not os.path.islink(path):
                os.chmod(path, 0o755 if os.stat(path).st_mode & 0o100 else 0o644)
