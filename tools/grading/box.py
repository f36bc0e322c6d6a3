"""How student code runs: isolated (bubblewrap) or not, with the limits of a build and of a
test case, within the grading's deadline, in a clean environment; without bubblewrap, as
root, as an unprivileged user that owns the build folder only while it builds and must be
unable to read the reference and the hidden tests. A full grading disk is the machine's
failure (NotGraded), never the student's."""
import dataclasses
import json
import os
import tempfile
import time
from dataclasses import dataclass

from . import sandbox
from .errors import GradeError, NotGraded, OutOfTime
from .grade_report import printable, say
from .users import USER_PYTHON, User


@dataclass
class Isolation:
    """How student code runs: isolated or not, and the limits of a build and of a test case."""
    isolate: bool
    build: sandbox.Limits
    test: sandbox.Limits
    jobs: int = 2
    # What student code must not read: the reference tree (the solutions), the student's own
    # tree, the instructor's hidden tests and home folders. It reads the grading tree instead
    # (a build: WORK/src and WORK/build; a test: WORK/build and the data).
    hidden: tuple = ()
    deadline: float = None  # time.monotonic() by which the whole grading ends (None: none)
    log: object = None  # where progress goes (None: stderr)
    # Without isolation, as root: the unprivileged user student code runs as (a
    # users.User). The grading tree is then readable to it, the build folder its own only
    # while it builds, each test case's folder its own; the rest is the grader's. (Isolated,
    # as root, each command runs as a user id of its own: sandbox.run picks it.)
    user: User = None
    disk: str = None  # the grading folder, whose disk a failed command may have found full

    @property
    def drop(self):
        return self.user is not None and not self.isolate


# Run as the student user: which of the paths it can open (a folder: list).
_ACCESS_PROBE = """import json, os, sys
seen = {}
for p in sys.argv[1:]:
    try:
        os.listdir(p) if os.path.isdir(p) else open(p, "rb").close()
        seen[p] = True
    except OSError:
        seen[p] = False
print(json.dumps(seen))
"""


def check_user_access(iso, work, secret):
    """Asks the student user itself (a command in the sandbox, as the tests run) what it can
    read: the grading tree it must, the reference tree and the hidden tests it must not.
    Raises GradeError (exit 2) naming what is wrong."""
    src = os.path.join(work, "src")
    wanted = [src, os.path.join(src, "CMakeLists.txt")]
    paths = wanted + [p for p in secret if p and os.path.exists(p)]
    with tempfile.TemporaryDirectory(prefix="probe-", dir=work) as folder:
        os.chmod(folder, 0o711)
        os.chown(folder, iso.user.uid, iso.user.gid)
        r = sandbox.run([USER_PYTHON, "-I", "-S", "-c", _ACCESS_PROBE] + paths,
                        sandbox.Limits(seconds=30, memory_mb=1024, output_mb=1), writable=[folder],
                        isolate=False, env=clean_env(folder), user=iso.user)
    try:
        seen = json.loads(r.stdout.decode())
    except ValueError:
        raise GradeError(f"grade: cannot run commands as user {iso.user.name} ({r.reason}: "
                         f"{r.stderr.decode(errors='replace').strip()[-200:]})", 2) from None
    for p in wanted:
        if not seen.get(p):
            raise GradeError(f"grade: user {iso.user.name} cannot read the grading tree {src}: "
                             "every folder above it must let others in (chmod o+x)", 2)
    for p in paths[len(wanted):]:
        if seen.get(p):
            raise GradeError(f"grade: user {iso.user.name} can read {p}: the reference solutions "
                             "and the hidden tests must be out of its reach (chmod o-rwx on it or "
                             "a folder above it)", 2)


def sandboxed(cmd, limits, iso, **kw):
    """sandbox.run with the isolation's settings, within its deadline: a run's time limit
    is cut to the time left, and OutOfTime is raised once none is left."""
    if iso.deadline is not None:
        left = iso.deadline - time.monotonic()
        if left <= 0:
            raise OutOfTime()
        if left < limits.seconds:
            limits = dataclasses.replace(limits, seconds=left)
    r = sandbox.run(cmd, limits, isolate=iso.isolate, hidden=iso.hidden,
                    user=iso.user if iso.drop else None, **kw)
    if not r.ok and iso.disk:  # now, before the grader cleans up what filled it
        trouble = disk_trouble(iso.disk)
        if trouble:
            raise NotGraded(trouble)
    if iso.deadline is not None and time.monotonic() >= iso.deadline:
        raise OutOfTime()
    return r


MIN_FREE_MB = 512  # what grading one tree may need on the grading disk, at most


def disk_trouble(path):
    """Why the disk of `path` cannot hold a grade (less free than MIN_FREE_MB, or
    BOXES_GRADE_MIN_FREE_MB), or None. Student code has its own space (sandbox.Limits
    disk_mb): a full grading disk is the machine's, or another program's, doing."""
    need = int(os.environ.get("BOXES_GRADE_MIN_FREE_MB") or MIN_FREE_MB) << 20
    try:
        info = os.statvfs(path)
    except OSError:
        return None
    free = info.f_bavail * info.f_frsize
    if free >= need:
        return None
    return (f"the grading disk is full: {free >> 20} MB free where grading needs {need >> 20} MB "
            f"({printable(path)})")


def clean_env(home):
    """The environment student code sees: no secrets of the instructor's shell."""
    env = {k: v for k, v in os.environ.items() if k in ("PATH", "LANG", "LC_ALL", "CC", "CXX", "TZ")}
    env.setdefault("PATH", "/usr/local/bin:/usr/bin:/bin")
    # glibc's malloc keeps up to 8 arenas of 64 MB address space per core: on a many-core
    # machine that alone would pass the memory limit.
    env.update(HOME=home, TMPDIR="/tmp", MALLOC_ARENA_MAX="2")
    return env


def write_private(path, text):
    """A file only the grader reads (a build log may quote the hidden tests)."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    os.fchmod(fd, 0o600)  # an older one may have been readable
    with os.fdopen(fd, "w") as f:
        f.write(text)


def refuse_without_isolation(opts, log=None):
    """The grader runs student code: without bubblewrap it refuses unless told otherwise."""
    if opts.no_isolation:
        say("WARNING: student code runs WITHOUT isolation (--no-isolation): only for code you trust", log)
        return
    problem = sandbox.isolation_problem()
    if problem:
        raise GradeError(f"grade: {problem}: refusing to run student code without isolation "
                         "(--no-isolation runs it unprotected, only for code you trust)", 2)
