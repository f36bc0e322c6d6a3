"""Students' submissions as the grader sees them: a folder, a git repository or an archive
(.zip, .tar, .tar.gz/.tgz, .tar.bz2, .tar.xz) per student, reduced to what the grader reads,
the C++ sources of the step folders (grade.py student_sources). Shared by the class
grader (grade_class.py) and the Gradescope autograder (gradescope.py).

Unpacking is defensive: an archive member is taken only when it is a regular file under a
`steps/NN_name/` folder with a source suffix; absolute paths, `..`, links and devices are
skipped, and a submission over MAX_FILES sources or MAX_BYTES in total is refused, so a
hostile archive can neither write outside the staging folder nor fill the disk. An archive
is refused before it is read past MAX_MEMBERS members or MAX_ARCHIVE_BYTES (its size, or
its members' declared sizes): a tar bomb costs a fraction of a second, not its unpacking.
Paths that cannot be staged are refused with the submission (a name longer than a file
system takes, a path that is both a file and a folder), so one bad archive costs its own
row only. A folder is read, never followed: only regular files, opened without following
a link (`read_tree` says which links, devices and FIFOs it refused and why).
"""
import hashlib
import io
import os
import re
import shutil
import stat
import struct
import subprocess
import tarfile
import zipfile

from .exercises import SOURCE_SUFFIXES

MAX_FILES = 2000  # step sources in one submission
MAX_BYTES = 20 << 20  # their total size
MAX_FILE_BYTES = 4 << 20  # one source file
# A whole archive: its members of any kind (a tree with its .git and build/ left out has a few
# hundred), and its size on disk and its members' declared sizes.
MAX_MEMBERS = 10000
MAX_ARCHIVE_BYTES = 256 << 20
MAX_NAME_BYTES = 255  # one component of a path (what ext4, XFS and tmpfs take)
MAX_PATH_BYTES = 1024  # a whole relative path
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
    if name.startswith("/"):
        return None
    parts = [p for p in name.split("/") if p not in ("", ".")]  # a//b and a/./b are a/b
    if ".." in parts or any(p in SKIP_PARTS for p in parts):
        return None
    name = "/".join(parts)
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
    check_paths(chosen)
    return chosen


def check_paths(rels):
    """Raises SubmissionError for relative paths that no file system could stage together:
    a name or a path too long, or a path that is a file and also a folder of another."""
    folders = set()
    for rel in rels:
        parts = rel.split("/")
        if len(rel.encode(errors="surrogateescape")) > MAX_PATH_BYTES:
            raise SubmissionError(f"a path longer than {MAX_PATH_BYTES} bytes ({rel[:60]}...)")
        long = [p for p in parts if len(p.encode(errors="surrogateescape")) > MAX_NAME_BYTES]
        if long:
            raise SubmissionError(f"a name longer than {MAX_NAME_BYTES} bytes ({long[0][:60]}...)")
        folders.update("/".join(parts[:k]) for k in range(1, len(parts)))
    both = sorted(folders.intersection(rels))
    if both:
        raise SubmissionError(f"{both[0]} is both a file and a folder in the submission")


def _read_limited(f, size):
    data = f.read(min(size, MAX_FILE_BYTES) + 1)
    if len(data) > MAX_FILE_BYTES:
        raise SubmissionError(f"a step source is larger than {MAX_FILE_BYTES >> 20} MB")
    return data


def _check_archive_size(path):
    size = os.path.getsize(path)
    if size > MAX_ARCHIVE_BYTES:
        raise SubmissionError(f"the archive is larger than {MAX_ARCHIVE_BYTES >> 20} MB")


class _Tally:
    """Counts an archive's members and their declared sizes; refuses past the limits."""

    def __init__(self, what="archive"):
        self.what, self.members, self.bytes = what, 0, 0

    def add(self, size=0):
        self.members += 1
        self.bytes += max(0, size)
        if self.members > MAX_MEMBERS:
            raise SubmissionError(f"more than {MAX_MEMBERS} files in the {self.what} (leave build/ "
                                  "and other generated folders out)")
        if self.bytes > MAX_ARCHIVE_BYTES:
            raise SubmissionError(f"the {self.what}'s files hold more than {MAX_ARCHIVE_BYTES >> 20} MB "
                                  "(leave build/ and other generated folders out)")


def zip_member_count(path):
    """The member count a zip's end-of-central-directory record declares (zip64 too), read
    before zipfile reads the whole central directory (a million entries take seconds and
    hundreds of MB there); None when there is no such record."""
    with open(path, "rb") as f:
        f.seek(0, os.SEEK_END)
        size = f.tell()
        f.seek(max(0, size - (22 + 65535)))
        tail = f.read()
        at = tail.rfind(b"PK\x05\x06")
        if at < 0 or len(tail) - at < 22:
            return None
        count = struct.unpack("<H", tail[at + 10:at + 12])[0]
        locator = at - 20
        if count == 0xFFFF and locator >= 0 and tail[locator:locator + 4] == b"PK\x06\x07":
            record = struct.unpack("<Q", tail[locator + 8:locator + 16])[0]
            f.seek(record)
            zip64 = f.read(56)
            if len(zip64) == 56 and zip64[:4] == b"PK\x06\x06":
                count = struct.unpack("<Q", zip64[32:40])[0]
        return count


def _from_zip(path):
    _check_archive_size(path)
    try:
        count = zip_member_count(path)
    except OSError as e:
        raise SubmissionError(f"not a readable zip archive ({e})") from e
    if count is not None and count > MAX_MEMBERS:
        raise SubmissionError(f"more than {MAX_MEMBERS} files in the archive (leave build/ and other "
                              "generated folders out)")
    try:
        z = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, OSError) as e:
        raise SubmissionError(f"not a readable zip archive ({e})") from e
    with z:
        candidates = []
        tally = _Tally()
        for info in z.infolist():
            tally.add(info.file_size)
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
            _check_archive_size(path_or_fileobj)
            t = tarfile.open(path_or_fileobj, "r:*")
        else:
            t = tarfile.open(fileobj=path_or_fileobj, mode="r:*")
    except (tarfile.TarError, OSError) as e:
        raise SubmissionError(f"not a readable tar archive ({e})") from e
    with t:
        candidates = []
        tally = _Tally()
        try:
            # Counted as each header is read, before the next one is looked for (which reads,
            # and for a compressed tar unpacks, the member's declared size).
            for info in t:
                tally.add(info.size)
                if not info.isreg():  # links, devices and folders are skipped
                    continue
                found = _step_relpath(info.name)
                if found:
                    candidates.append((*found, info.size, info))
        except (tarfile.TarError, OSError, EOFError) as e:
            raise SubmissionError(f"not a readable tar archive ({e})") from e
        chosen = _choose(candidates)
        files = {}
        for rel, (size, info) in chosen.items():
            f = t.extractfile(info)
            files[rel] = _read_limited(f, size) if f else b""
        return files


_KINDS = ((stat.S_ISLNK, "a symbolic link"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a device"),
          (stat.S_ISBLK, "a device"), (stat.S_ISSOCK, "a socket"))


def _kind(mode):
    return next((name for test, name in _KINDS if test(mode)), "not a regular file")


def _scan_folder(path, refused=None, only=None):
    """[(prefix, relative step path, size, data)] of the step sources under `path`, read
    without following any link: every folder and file is opened relative to its parent
    (O_NOFOLLOW), so a link anywhere (to a folder, to the reference's solutions through
    /proc/self/cwd, to a root-only file), a device (/dev/zero) or a FIFO is never read.
    Those found under a steps/ folder go into `refused` as "PATH: why". `only`: the one
    folder of `path` to scan (e.g. "steps"). Past MAX_FILES sources, MAX_BYTES of them or
    MAX_MEMBERS entries: SubmissionError."""
    found = []
    tally = _Tally("folder")
    total = 0

    def note(rel, why):
        if refused is not None and re.search(r"(^|/)steps(/|$)", rel):
            refused.append(f"{rel}: {why}, not read (only regular files are graded)")

    def scan(dirfd, rel):
        nonlocal total
        with os.scandir(dirfd) as entries:
            names = sorted(e.name for e in entries)
        for name in names:
            sub = f"{rel}/{name}" if rel else name
            tally.add()
            try:
                info = os.stat(name, dir_fd=dirfd, follow_symlinks=False)
            except OSError:
                continue  # gone meanwhile
            if stat.S_ISDIR(info.st_mode):
                if name in SKIP_PARTS:
                    continue
                try:
                    fd = os.open(name, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW, dir_fd=dirfd)
                except OSError as e:
                    note(sub, f"a folder that cannot be opened ({e.strerror})")
                    continue
                try:
                    scan(fd, sub)
                finally:
                    os.close(fd)
                continue
            step = _step_relpath(sub)
            if not stat.S_ISREG(info.st_mode):
                note(sub, _kind(info.st_mode))
                continue
            if not step:
                continue
            if len(found) >= MAX_FILES:
                raise SubmissionError(f"more than {MAX_FILES} step sources")
            total += info.st_size
            if total > MAX_BYTES:
                raise SubmissionError(f"the step sources exceed {MAX_BYTES >> 20} MB")
            try:
                fd = os.open(name, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK, dir_fd=dirfd)
            except OSError as e:
                note(sub, f"cannot be opened ({e.strerror})")
                continue
            with os.fdopen(fd, "rb") as f:
                if not stat.S_ISREG(os.fstat(f.fileno()).st_mode):  # swapped since the stat
                    note(sub, _kind(os.fstat(f.fileno()).st_mode))
                    continue
                found.append((*step, info.st_size, _read_limited(f, info.st_size)))

    try:
        top = os.open(path, os.O_RDONLY | os.O_DIRECTORY)
    except OSError as e:
        raise SubmissionError(f"cannot open the folder ({e.strerror})") from e
    try:
        if only is None:
            scan(top, "")
            return found
        try:
            info = os.stat(only, dir_fd=top, follow_symlinks=False)
        except FileNotFoundError:
            return found
        if not stat.S_ISDIR(info.st_mode):
            note(only, _kind(info.st_mode))
            return found
        fd = os.open(only, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW, dir_fd=top)
        try:
            scan(fd, only)
        finally:
            os.close(fd)
    finally:
        os.close(top)
    return found


def _from_folder(path):
    chosen = _choose(_scan_folder(path))
    return {rel: data for rel, (size, data) in chosen.items()}


def read_tree(path, refused):
    """{"steps/NN_name/file.cpp": bytes} of the step sources of the workbook tree `path`
    (its own steps/ folder, not one found deeper), read as a submission folder is: regular
    files only, never through a link, within the same limits. Each link, device or FIFO
    under steps/ is refused, its reason appended to `refused`. {} when there is none;
    SubmissionError past a limit."""
    candidates = [c for c in _scan_folder(path, refused, only="steps") if c[0] == ""]
    if not candidates:
        return {}
    return {rel: data for rel, (size, data) in _choose(candidates).items()}


def _from_bare_git(path):
    """A bare repository (HEAD, objects/): its HEAD commit through git archive, read up to
    MAX_ARCHIVE_BYTES (a larger one is refused, not held in memory)."""
    try:
        with subprocess.Popen(["git", "--git-dir", path, "archive", "--format=tar", "HEAD"],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE) as p:
            try:
                data = p.stdout.read(MAX_ARCHIVE_BYTES + 1)
                if len(data) > MAX_ARCHIVE_BYTES:
                    p.kill()
                    raise SubmissionError(f"the repository's files hold more than {MAX_ARCHIVE_BYTES >> 20} MB")
                err = p.stderr.read(4096)
                p.wait(timeout=120)
            finally:
                if p.returncode is None:
                    p.kill()
    except (OSError, subprocess.TimeoutExpired) as e:
        raise SubmissionError(f"git archive failed ({e})") from e
    if p.returncode != 0:
        raise SubmissionError("git archive failed: " + err.decode(errors="replace").strip()[:200])
    return _from_tar(io.BytesIO(data))


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


def write_files(dest, files):
    """Writes {relative path: bytes or text (UTF-8)} under the folder dest, making folders as
    needed; a path that would land outside dest raises SubmissionError, and so does a link
    already there (it is not written through). Returns dest. (The one "write these files
    into a tree" of the tools and their tests.)"""
    for rel, data in files.items():
        target = os.path.join(dest, rel)
        if not os.path.abspath(target).startswith(os.path.abspath(dest) + os.sep):
            raise SubmissionError(f"unsafe path {rel}")
        os.makedirs(os.path.dirname(target), exist_ok=True)
        try:
            fd = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_NOFOLLOW, 0o666)
        except OSError as e:
            if os.path.islink(target):
                raise SubmissionError(f"{rel} is a link: not written through") from e
            raise
        with os.fdopen(fd, "wb") as f:
            f.write(data.encode() if isinstance(data, str) else data)
    return dest


def stage(files, dest):
    """Writes the sources into a fresh folder dest (a tree the grader can read). Their paths
    come from _step_relpath (no '..', not absolute); write_files checks again."""
    if os.path.exists(dest):
        shutil.rmtree(dest)
    return write_files(dest, files)
