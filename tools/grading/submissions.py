"""Students' submissions as the grader sees them: a folder, a git repository or an archive
(.zip, .tar, .tar.gz/.tgz, .tar.bz2, .tar.xz) per student, reduced to what the grader reads,
the C++ sources of the step folders (grade.py student_sources). Shared by the class
grader (grade_class.py) and the Gradescope autograder (gradescope.py).

Unpacking is defensive: an archive member is taken only when it is a regular file under a
`steps/NN_name/` folder with a source suffix; absolute paths, `..`, links and devices are
skipped, and a submission over MAX_FILES sources or MAX_BYTES in total is refused, so a
hostile archive can neither write outside the staging folder nor fill the disk.
"""
import hashlib
import io
import os
import re
import shutil
import subprocess
import tarfile
import zipfile

from .exercises import SOURCE_SUFFIXES

MAX_FILES = 2000  # step sources in one submission
MAX_BYTES = 20 << 20  # their total size
MAX_FILE_BYTES = 4 << 20  # one source file
ARCHIVE_SUFFIXES = (".zip", ".tar", ".tar.gz", ".tgz", ".tar.bz2", ".tbz2", ".tar.xz", ".txz")
STEP_PATH = re.compile(r"(^|/)steps/(\d\d_[A-Za-z0-9_.-]+/.*)$")
SKIP_PARTS = {"__MACOSX", ".git", "build", "out", "node_modules"}


class SubmissionError(Exception):
    """A submission that cannot be graded (the message says why, for the class table)."""


def student_name(entry):
    """The student's name from a folder or archive name: "alice.tar.gz" -> "alice"."""
    for suffix in ARCHIVE_SUFFIXES:
        if entry.lower().endswith(suffix):
            return entry[: -len(suffix)]
    return entry


def is_submission(path):
    return os.path.isdir(path) or path.lower().endswith(ARCHIVE_SUFFIXES)


def _step_relpath(member):
    """'alice/steps/01_triangle/triangle.cpp' -> ('alice/', 'steps/01_triangle/triangle.cpp'),
    or None when the member is not a step source or its path is unsafe."""
    name = member.replace("\\", "/")
    parts = name.split("/")
    if name.startswith("/") or ".." in parts or any(p in SKIP_PARTS for p in parts):
        return None
    m = STEP_PATH.search(name)
    if not m or not name.endswith(SOURCE_SUFFIXES):
        return None
    prefix = name[: m.start(2) - len("steps/")]
    return prefix, "steps/" + m.group(2)


def _choose(candidates):
    """{relative path: reader} of the candidates [(prefix, rel, size, reader)] under the
    shortest prefix (the tree's root inside the archive), with the size limits applied."""
    if not candidates:
        raise SubmissionError("no step sources (steps/NN_name/*.cpp) in the submission")
    root = min((c[0] for c in candidates), key=lambda p: (p.count("/"), p))
    chosen = {rel: (size, reader) for prefix, rel, size, reader in candidates if prefix == root}
    if len(chosen) > MAX_FILES:
        raise SubmissionError(f"more than {MAX_FILES} step sources")
    if sum(s for s, _ in chosen.values()) > MAX_BYTES:
        raise SubmissionError(f"the step sources exceed {MAX_BYTES >> 20} MB")
    big = [rel for rel, (s, _) in chosen.items() if s > MAX_FILE_BYTES]
    if big:
        raise SubmissionError(f"{big[0]} is larger than {MAX_FILE_BYTES >> 20} MB")
    return chosen


def _read_limited(f, size):
    data = f.read(min(size, MAX_FILE_BYTES) + 1)
    if len(data) > MAX_FILE_BYTES:
        raise SubmissionError(f"a step source is larger than {MAX_FILE_BYTES >> 20} MB")
    return data


def _from_zip(path):
    try:
        z = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, OSError) as e:
        raise SubmissionError(f"not a readable zip archive ({e})") from e
    with z:
        candidates = []
        for info in z.infolist():
            mode = (info.external_attr >> 16) & 0o170000
            if info.is_dir() or mode not in (0, 0o100000):  # links and devices are skipped
                continue
            found = _step_relpath(info.filename)
            if found:
                candidates.append((*found, info.file_size, info))
        chosen = _choose(candidates)
        files = {}
        for rel, (size, info) in chosen.items():
            with z.open(info) as f:
                files[rel] = _read_limited(f, size)
        return files


def _from_tar(path_or_fileobj):
    try:
        if isinstance(path_or_fileobj, str):
            t = tarfile.open(path_or_fileobj, "r:*")
        else:
            t = tarfile.open(fileobj=path_or_fileobj, mode="r:*")
    except (tarfile.TarError, OSError) as e:
        raise SubmissionError(f"not a readable tar archive ({e})") from e
    with t:
        candidates = []
        for info in t:
            if not info.isreg():  # links, devices and folders are skipped
                continue
            found = _step_relpath(info.name)
            if found:
                candidates.append((*found, info.size, info))
            if len(candidates) > 10 * MAX_FILES:
                raise SubmissionError("too many files in the archive")
        chosen = _choose(candidates)
        files = {}
        for rel, (size, info) in chosen.items():
            f = t.extractfile(info)
            files[rel] = _read_limited(f, size) if f else b""
        return files


def _from_folder(path):
    candidates = []
    for base, dirs, names in os.walk(path):  # os.walk does not follow links to folders
        dirs[:] = sorted(d for d in dirs if d not in SKIP_PARTS)
        for n in names:
            full = os.path.join(base, n)
            if os.path.islink(full) or not os.path.isfile(full):
                continue
            found = _step_relpath(os.path.relpath(full, path).replace(os.sep, "/"))
            if found:
                candidates.append((*found, os.path.getsize(full), full))
            if len(candidates) > 10 * MAX_FILES:
                raise SubmissionError("too many files in the folder")
    chosen = _choose(candidates)
    files = {}
    for rel, (size, full) in chosen.items():
        with open(full, "rb") as f:
            files[rel] = _read_limited(f, size)
    return files


def _from_bare_git(path):
    """A bare repository (HEAD, objects/): its HEAD commit through git archive."""
    try:
        r = subprocess.run(["git", "--git-dir", path, "archive", "--format=tar", "HEAD"],
                           capture_output=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired) as e:
        raise SubmissionError(f"git archive failed ({e})") from e
    if r.returncode != 0:
        raise SubmissionError("git archive failed: " + r.stderr.decode(errors="replace").strip()[:200])
    return _from_tar(io.BytesIO(r.stdout))


def read_submission(path):
    """{"steps/NN_name/file.cpp": bytes} of one submission (folder, git repository or
    archive); raises SubmissionError saying why it cannot be graded."""
    if os.path.isdir(path):
        if os.path.isfile(os.path.join(path, "HEAD")) and os.path.isdir(os.path.join(path, "objects")):
            return _from_bare_git(path)
        # A git working tree is a folder: what is checked out is what is graded.
        return _from_folder(path)
    lower = path.lower()
    if lower.endswith(".zip"):
        return _from_zip(path)
    if lower.endswith(ARCHIVE_SUFFIXES):
        return _from_tar(path)
    raise SubmissionError("not a folder or an archive")


def content_hash(files):
    """sha256 over the graded sources (path and content, in order)."""
    h = hashlib.sha256()
    for rel in sorted(files):
        h.update(rel.encode() + b"\0" + hashlib.sha256(files[rel]).digest())
    return h.hexdigest()


def stage(files, dest):
    """Writes the sources into a fresh folder dest (a tree the grader can read)."""
    if os.path.exists(dest):
        shutil.rmtree(dest)
    for rel, data in files.items():
        target = os.path.join(dest, rel)
        # The relative paths come from _step_relpath (no '..', not absolute): stay inside.
        if not os.path.abspath(target).startswith(os.path.abspath(dest) + os.sep):
            raise SubmissionError(f"unsafe path {rel}")
        os.makedirs(os.path.dirname(target), exist_ok=True)
        with open(target, "wb") as f:
            f.write(data)
    return dest
