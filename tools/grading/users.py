"""The users sandboxed commands run as: an unprivileged account (without isolation, as
root), the user id of its own a command gets under bubblewrap as root, the processes of a
user (one reading of /proc), killing them, and lending folders to a user for a run."""
import contextlib
import ctypes
import os
import pwd
import shutil
import stat
import subprocess
import sys
import threading
import time
from dataclasses import dataclass

from .bubblewrap import setpriv_program


@dataclass(frozen=True)
class User:
    """The unprivileged account that runs commands without isolation when the grader is
    root (grading_user)."""
    name: str
    uid: int
    gid: int


def grading_user(name):
    """The User called `name`; ValueError (one line) when there is none or it is root."""
    try:
        entry = pwd.getpwnam(name)
    except KeyError:
        raise ValueError(f"there is no user {name!r} (as root: useradd --system --no-create-home "
                         f"--shell /usr/sbin/nologin {name})") from None
    if entry.pw_uid == 0 or entry.pw_gid == 0:
        raise ValueError(f"user {name!r} is root or in root's group: student code needs an "
                         "unprivileged user")
    return User(name, entry.pw_uid, entry.pw_gid)


def processes():
    """{pid: the fields of /proc/PID/status} of every process there now (one that ends
    meanwhile is left out): the one reading of /proc for the sandbox and its tests."""
    found = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/status") as f:
                found[int(entry)] = dict((k, v.strip()) for k, v in (line.split(":", 1) for line in f if ":" in line))
        except OSError:
            pass  # gone meanwhile
    return found


def user_tasks(uid):
    """Threads of all processes whose real user is uid (what RLIMIT_NPROC counts)."""
    count = 0
    for fields in processes().values():
        try:
            if int(fields["Uid"].split()[0]) == uid:
                count += int(fields["Threads"])
        except (KeyError, ValueError, IndexError):
            pass
    return count


def processes_of(uid, state=None):
    """[(pid, parent pid)] of the processes whose real or effective user is uid, with
    the state letter `state` only (e.g. "Z", a zombie) or, by default, those alive."""
    found = []
    for pid, fields in processes().items():
        try:
            ids = fields["Uid"].split()
            letter = fields["State"].split()[0]
            if uid in (int(ids[0]), int(ids[1])) and (letter == state if state else letter not in "ZX"):
                found.append((pid, int(fields["PPid"])))
        except (KeyError, ValueError, IndexError):
            pass
    return found


# A Python the user can run: the grader's own may live in root's home (pyenv, a venv).
USER_PYTHON = shutil.which("python3", path="/usr/bin:/bin") or sys.executable


# kill(-1) as the user: the kernel signals every process of that user in one pass (a fork
# bomb cannot outrun it) and spares the caller.
_KILLER = "import os\ntry:\n    os.kill(-1, 9)\nexcept OSError:\n    pass\n"


def kill_user(user):
    """SIGKILL to every process of `user`, until /proc shows none alive. Returns how many
    were left (0 but for a kernel that cannot keep up)."""
    for attempt in range(100):
        if not processes_of(user.uid):
            return 0
        subprocess.run([USER_PYTHON, "-I", "-S", "-c", _KILLER], user=user.uid, group=user.gid,
                       extra_groups=[], env={}, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, check=False)
        time.sleep(min(0.01 * attempt, 0.1))
    return len(processes_of(user.uid))


_subreaper = False


def become_subreaper():
    """The grader adopts the orphans of its commands (prctl PR_SET_CHILD_SUBREAPER), so it
    can reap them: a container's first process may never reap, and unreaped zombies still
    count against the user's RLIMIT_NPROC."""
    global _subreaper
    if not _subreaper:
        try:
            ctypes.CDLL(None, use_errno=True).prctl(36, 1, 0, 0, 0)  # PR_SET_CHILD_SUBREAPER
        except (OSError, AttributeError):
            pass
        _subreaper = True


def reap_orphans(user):
    # Only the user's zombies: every command of that user has ended (one runs at a time),
    # so none of them is a Popen another thread still waits for.
    for pid, parent in processes_of(user.uid, state="Z"):
        if parent == os.getpid():
            try:
                os.waitpid(pid, os.WNOHANG)
            except ChildProcessError:
                pass


_user_locks = {}


_user_locks_lock = threading.Lock()


def user_lock(user):
    with _user_locks_lock:
        return _user_locks.setdefault(user.uid, threading.Lock())


BOX_UID_BASE = 2130706432  # 0x7F000000: far above login users, system users and subuid ranges


_BOX_SLOTS = 64  # sandboxed commands of one grader at once


_box_free = list(range(_BOX_SLOTS))


_box_lock = threading.Lock()


_warned_no_setpriv = False


@contextlib.contextmanager
def box_user(user):
    """The user an isolated command becomes: `user` when given; as root a fresh user id of
    its own, which no account, file or other command of this machine has (from
    BOXES_SANDBOX_UID_BASE, by this process's id and a free slot); else None (bubblewrap's
    "nobody" in a user namespace). Without setpriv, root keeps the user namespace, whose
    nobody is root outside (said once)."""
    global _warned_no_setpriv
    if os.geteuid() != 0:
        yield None
        return
    if not setpriv_program():
        if not _warned_no_setpriv:
            _warned_no_setpriv = True
            print("sandbox: WARNING: no setpriv (util-linux): as root the sandbox runs as root's "
                  "user outside its namespace", file=sys.stderr)
        yield None
        return
    if user is not None:
        yield user
        return
    with _box_lock:
        if not _box_free:
            raise RuntimeError(f"sandbox: more than {_BOX_SLOTS} sandboxed commands at once")
        slot = _box_free.pop(0)
    try:
        base = int(os.environ.get("BOXES_SANDBOX_UID_BASE") or BOX_UID_BASE)
        uid = base + (os.getpid() % 4096) * _BOX_SLOTS + slot
        yield User(f"uid {uid}", uid, uid)
    finally:
        with _box_lock:
            _box_free.append(slot)


def _chown_tree(path, uid, gid):
    """chown -R without following links; a file with more than one hard link is left alone
    (it may be another's file, linked in)."""
    if not os.path.lexists(path):
        return
    os.lchown(path, uid, gid)
    for d, dirs, files in os.walk(path):
        for n in dirs + files:
            p = os.path.join(d, n)
            try:
                info = os.lstat(p)
                if stat.S_ISDIR(info.st_mode) or info.st_nlink == 1:
                    os.lchown(p, uid, gid)
            except FileNotFoundError:
                pass


@contextlib.contextmanager
def lent(paths, user):
    """The folders (with what is in them) and files `paths` are `user`'s while the command
    runs, the caller's again afterwards: what the command made there, the grader then owns,
    and no later command of that user can change it."""
    if user is None or not paths:
        yield
        return
    for p in paths:
        _chown_tree(p, user.uid, user.gid)
    try:
        yield
    finally:
        for p in paths:
            _chown_tree(p, os.getuid(), os.getgid())
