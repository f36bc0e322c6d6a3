"""Runs one untrusted command isolated and limited: the grader's student builds and test
runs (grade.py imports this module), and tools/grading/sandbox.sh on the command line.

usage: tools/grading/sandbox.sh [--time S] [--memory MB] [--output MB] [--processes N]
                                [--dir DIR] [--no-isolation [--user NAME]] -- COMMAND [ARGS...]

Isolation (bubblewrap): the command sees the system's programs and libraries read-only
(/usr, /etc and the links of a merged /usr; nothing else of the machine: no home, no
/work, /srv or /var, no other student's folder), the folders it is given (DIR, default: a
fresh temporary folder, the only writable place and the working directory), a private /tmp
and /dev/shm of at most the output limit each, no network (an own, empty network
namespace), an own PID namespace, no capabilities, killed with its parent. As root it runs
as a user id of its own that owns no file of the machine (a fresh one per command, from
BOXES_SANDBOX_UID_BASE, default 2130706432; setpriv drops to it inside the sandbox) and DIR
is lent to that user for the run; otherwise as "nobody" in a user namespace, with no
further user namespaces.
Limits (setrlimit, inherited by every process the command starts): wall-clock seconds (the
whole run), CPU seconds (per process: the wall time times the cores, so a busy loop in
every thread still stops), address space per process, the size of any file written, and
the bytes the command prints on stdout and stderr together. The number of processes and
threads (a fork bomb): as root a pids cgroup of its own (the kernel does not apply
RLIMIT_NPROC to root), else RLIMIT_NPROC above the user's current count.

Without isolation, run as root with --user NAME (an unprivileged account, e.g. Gradescope's
setup.sh creates one): the command runs as that user with no supplementary groups, so the
kernel's file permissions keep it from what that user may not read or write, and
RLIMIT_NPROC binds it (the kernel does not apply it to root). Every process of that user is
killed when the command ends, whatever session or process group it moved to: no daemon
outlives its run. The commands of one user run one at a time (the kill spares nothing of
that user).

On the command line the command's stdout and stderr go to DIR/stdout.txt and
DIR/stderr.txt (their first bytes, up to the output limit) and one line
"sandbox: RESULT" goes to stdout: ok | failed: exit N | time limit | memory limit |
output limit | crashed: SIGNAME. Exit status: 0 ok, 1 failed, 3 limit or crash, 2 usage
or refused (bubblewrap cannot create namespaces here and no --no-isolation).
Environment: BOXES_BWRAP names the bubblewrap program (default: bwrap on PATH);
BOXES_SANDBOX_SYSTEM adds folders the sandbox shows read-only (colon-separated, e.g. a
compiler under /opt).
"""
import argparse
import contextlib
import ctypes
import functools
import itertools
import math
import os
import pwd
import resource
import selectors
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass

try:  # a module of tools.grading, or run as a script (sandbox.sh)
    from .strict_numbers import MAX_MB, MAX_SECONDS, decimal, integer
except ImportError:
    from strict_numbers import MAX_MB, MAX_SECONDS, decimal, integer

# What the C++ runtime, glibc, GCC and Python print when an allocation is refused: under an
# address-space limit that is the normal way a memory hog ends.
MEMORY_SIGNS = (b"std::bad_alloc", b"bad_alloc", b"Cannot allocate memory", b"out of memory",
                b"virtual memory exhausted", b"MemoryError")


@dataclass
class Limits:
    seconds: float = 10.0  # wall clock, the whole run
    memory_mb: int = 1024  # address space of each process
    output_mb: float = 16.0  # stdout + stderr together, and any one file written
    file_mb: float = 0.0  # any one file written, when it must differ from output_mb (a build)
    processes: int = 256  # processes and threads the command may have at once
    disk_mb: float = 64.0  # all files of a scratch folder together (run's `scratch`, isolated)

    def cpu_seconds(self):
        return int(self.seconds * usable_cpus()) + 1


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


def _cpu_quota(folder):
    """The CPUs one cgroup folder's quota allows (cgroup v2 cpu.max, v1 cpu.cfs_quota_us
    over cpu.cfs_period_us), or None without a quota there."""
    try:
        with open(os.path.join(folder, "cpu.max")) as f:
            quota, period = (f.read().split() + ["100000"])[:2]
        return None if quota == "max" else int(quota) / int(period)
    except (OSError, ValueError, ZeroDivisionError):
        pass
    try:
        with open(os.path.join(folder, "cpu.cfs_quota_us")) as f:
            quota = int(f.read())
        with open(os.path.join(folder, "cpu.cfs_period_us")) as f:
            period = int(f.read())
        return None if quota <= 0 or period <= 0 else quota / period
    except (OSError, ValueError):
        return None


def cgroup_cpu_quota(proc_cgroup="/proc/self/cgroup", mounts="/proc/self/mounts"):
    """The tightest CPU quota on this process's cgroup and its parents (in CPUs, e.g. 0.5
    for Gradescope's default half a virtual CPU), or None when there is none. In a container
    the cgroup's path may not exist below the mount (it is the mount's root): then the
    mount's root is read."""
    try:
        with open(proc_cgroup) as f:
            entries = [line.strip().split(":", 2) for line in f if line.count(":") >= 2]
        with open(mounts) as f:
            mounted = [line.split() for line in f]
    except OSError:
        return None
    quotas = []
    for _, controllers, path in entries:
        for m in mounted:
            if len(m) < 4:
                continue
            if not ((controllers == "" and m[2] == "cgroup2") or
                    (m[2] == "cgroup" and "cpu" in controllers.split(",") and "cpu" in m[3].split(","))):
                continue
            folder = os.path.normpath(os.path.join(m[1], path.lstrip("/")))
            while not os.path.isdir(folder) and folder.startswith(m[1] + "/"):
                folder = os.path.dirname(folder)
            while True:
                q = _cpu_quota(folder)
                if q is not None:
                    quotas.append(q)
                if folder == m[1] or not folder.startswith(m[1] + "/"):
                    break
                folder = os.path.dirname(folder)
    return min(quotas) if quotas else None


@functools.cache  # neither changes while the grader runs
def usable_cpus():
    """The CPUs this process may use: its affinity, cut to the cgroup's CPU quota (rounded
    up, at least 1). In a container os.cpu_count() is the host's."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        cpus = os.cpu_count() or 1
    quota = cgroup_cpu_quota()
    if quota is not None:
        cpus = min(cpus, max(1, math.ceil(quota)))
    return max(1, cpus)


@dataclass
class Result:
    status: str  # ok | failed | time limit | memory limit | output limit | crashed
    reason: str  # ok | failed: exit N | time limit | memory limit | output limit | crashed: SIGSEGV
    returncode: int
    stdout: bytes  # the first bytes (up to `keep`)
    stderr: bytes
    seconds: float

    @property
    def ok(self):
        return self.status == "ok"


class Stopped(Exception):
    """stop_all() was called: this process runs no more sandboxed commands."""


_stop = threading.Event()
_live = set()  # the Popen of every command running now (the class grader runs them on threads)
_live_lock = threading.Lock()


def stop_all():
    """Kills every command running under the sandbox in this process and refuses new ones
    (run raises Stopped): the class grader's Ctrl-C, with graders on several threads."""
    _stop.set()
    with _live_lock:
        running = list(_live)
    for p in running:
        if p.returncode is not None:  # reaped already: its number may be another's now
            continue
        try:
            os.killpg(p.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


def bwrap_program():
    return os.environ.get("BOXES_BWRAP") or shutil.which("bwrap") or ""


def isolation_problem():
    """None when bubblewrap can isolate here, else one line saying why not. The probe runs
    what the sandbox runs, not a smaller command: the same bubblewrap command line (devices,
    /proc, a private /tmp of limited size, a covered folder, a writable bind, the
    namespaces) under the same limits. Docker's default seccomp profile, for one, refuses
    the namespaces, and a container may allow them but refuse mounting /proc."""
    bwrap = bwrap_program()
    if not bwrap:
        return "bubblewrap is not installed (tools/deps.sh grade installs it)"
    folder = tempfile.mkdtemp(prefix="boxes-probe-")
    try:
        covered = os.path.join(folder, "covered")
        os.makedirs(os.path.join(covered, "shown"))
        r = run(["true"], Limits(seconds=30, memory_mb=1024, output_mb=1), writable=[folder],
                hidden=[covered], readable=[os.path.join(covered, "shown")])
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    if r.ok:
        return None
    if r.returncode == 127 and r.reason.startswith("failed: cannot start"):
        return f"bubblewrap ({bwrap}) does not run: {r.stderr.decode(errors='replace')}"
    first = (r.stderr.decode(errors="replace").strip().splitlines() or [r.reason])[0]
    return f"bubblewrap cannot create namespaces here ({first[:200]})"


@functools.cache
def _bwrap_help(program):
    try:
        r = subprocess.run([program, "--help"], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return ""
    return r.stdout + r.stderr


def bwrap_has(option):
    """Whether this bubblewrap knows a command-line option (--disable-userns came with
    0.8; Ubuntu 22.04 has 0.6)."""
    return option in _bwrap_help(bwrap_program()).split()


def _namespaces(user=None):
    """Without `user`: an own user namespace as "nobody" with no capabilities: root outside
    gets no power inside (no remounting the read-only system, no raising the limits). Where
    bubblewrap is older than 0.8 the sandbox may create further user namespaces; the mounts
    it inherits stay locked in them, and the limits were set outside. With `user` (the
    grader is root): no user namespace, so that the command's user id is `user`'s outside
    too (one that owns nothing); bubblewrap keeps only what it needs to enter that user's
    working folder and what setpriv needs to become it (all of which setpriv then drops)."""
    if user is None:
        flags = ["--unshare-all", "--unshare-user", "--uid", "65534", "--gid", "65534", "--cap-drop", "ALL"]
        if bwrap_has("--disable-userns"):
            flags.append("--disable-userns")
    else:
        flags = ["--unshare-ipc", "--unshare-pid", "--unshare-net", "--unshare-uts", "--unshare-cgroup-try",
                 "--cap-drop", "ALL", "--cap-add", "CAP_SETUID", "--cap-add", "CAP_SETGID",
                 "--cap-add", "CAP_SETPCAP", "--cap-add", "CAP_DAC_OVERRIDE"]  # to enter the user's folder
    return flags + ["--die-with-parent", "--new-session"]


def setpriv_program():
    return shutil.which("setpriv", path="/usr/bin:/bin") or ""


def become(user):
    """The command prefix, inside the sandbox, that becomes `user` for good: its ids, no
    groups, no capabilities (bounding set too), no new privileges (setuid programs stay
    what they are)."""
    return [setpriv_program(), f"--reuid={user.uid}", f"--regid={user.gid}", "--clear-groups",
            "--inh-caps=-all", "--bounding-set=-all", "--no-new-privs", "--"]


# What the sandbox shows of the system, read-only: the programs, libraries and headers
# (/usr), their configuration (/etc: the compilers' alternatives, ld.so.cache), and the
# top-level links of a merged /usr (or the folders themselves where /usr is not merged).
SYSTEM_DIRS = ("/usr", "/etc")
SYSTEM_LINKS = ("/bin", "/sbin", "/lib", "/lib32", "/lib64", "/libx32")


def system_mounts():
    args = []
    extra = [d for d in os.environ.get("BOXES_SANDBOX_SYSTEM", "").split(":") if d.startswith("/")]
    for d in SYSTEM_DIRS + tuple(extra):
        if os.path.isdir(d):
            args += ["--ro-bind", d, d]
    for d in SYSTEM_LINKS:
        if os.path.islink(d):
            args += ["--symlink", os.readlink(d), d]
        elif os.path.isdir(d):
            args += ["--ro-bind", d, d]
    return args


def _inside(path, folder):
    return path == folder or path.startswith(folder.rstrip("/") + "/")


def bwrap_prefix(writable, cwd, tmp_bytes, hidden=(), readable=(), scratch=None, scratch_bytes=0,
                 outputs=(), user=None):
    """bubblewrap arguments: the system read-only (system_mounts) and nothing else of the
    machine but the folders given: `readable` ones read-only, `writable` ones read-write,
    `scratch` (the working folder) a fresh tmpfs of scratch_bytes with the host files
    `outputs` bound into it read-write; a private /tmp and /dev/shm of tmp_bytes each, /dev
    and /proc of the sandbox's own. `hidden` folders inside the system folders are replaced
    by empty ones (folders outside them are not there anyway). `user` (as root): the
    namespaces for becoming that user (become)."""
    prefix = [bwrap_program()] + system_mounts() + ["--dev", "/dev", "--proc", "/proc"]
    size = ["--size", str(int(tmp_bytes))] if bwrap_has("--size") else []
    covers = []
    for d in hidden:
        inside_another = any(d != h and _inside(d, h) for h in hidden)
        shown = any(_inside(d, s) for s in SYSTEM_DIRS)
        if os.path.isdir(d) and shown and d not in SYSTEM_DIRS and not inside_another:
            covers.append(d)
            prefix += ["--tmpfs", d]
    prefix += size + ["--perms", "1777", "--tmpfs", "/tmp"]
    prefix += size + ["--perms", "1777", "--tmpfs", "/dev/shm"]
    # The folders above a bound one: bubblewrap would make them 0700 (a user that is not
    # root could not reach the folder by its path); those of the system exist already.
    made = set(SYSTEM_DIRS) | {"/", "/tmp", "/dev", "/proc"}
    for d in [r for r in readable if os.path.exists(r)] + list(writable) + ([scratch] if scratch else []):
        parts = d.strip("/").split("/")[:-1]
        for k in range(1, len(parts) + 1):
            up = "/" + "/".join(parts[:k])
            shown = any(_inside(up, s) for s in SYSTEM_DIRS) and not any(_inside(up, c) for c in covers)
            if up not in made and not shown:
                made.add(up)
                prefix += ["--perms", "0755", "--dir", up]
    for d in readable:
        if os.path.exists(d):
            prefix += ["--ro-bind", d, d]
    for d in writable:
        prefix += ["--bind", d, d]
    if scratch:
        prefix += (["--size", str(int(scratch_bytes))] if bwrap_has("--size") else []) + \
            ["--perms", "1777", "--tmpfs", scratch]
        for f in outputs:
            prefix += ["--bind", f, f]
    for d in covers:  # the empty covers stay read-only (after the binds made their mount points)
        prefix += ["--remount-ro", d]
    return prefix + ["--chdir", cwd] + _namespaces(user)


def _user_tasks(uid):
    """Threads of all processes whose real user is uid (what RLIMIT_NPROC counts)."""
    count = 0
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/status") as f:
                fields = dict(line.split(":", 1) for line in f if ":" in line)
            if int(fields["Uid"].split()[0]) == uid:
                count += int(fields["Threads"])
        except (OSError, KeyError, ValueError):
            pass  # gone meanwhile
    return count


def _processes_of(uid, state=None):
    """[(pid, parent pid)] of the processes whose real or effective user is uid, with
    the state letter `state` only (e.g. "Z", a zombie) or, by default, those alive."""
    found = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/status") as f:
                fields = dict(line.split(":", 1) for line in f if ":" in line)
            ids = fields["Uid"].split()
            letter = fields["State"].split()[0]
            if uid in (int(ids[0]), int(ids[1])) and (letter == state if state else letter not in "ZX"):
                found.append((int(entry), int(fields["PPid"])))
        except (OSError, KeyError, ValueError, IndexError):
            pass  # gone meanwhile
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
        if not _processes_of(user.uid):
            return 0
        subprocess.run([USER_PYTHON, "-I", "-S", "-c", _KILLER], user=user.uid, group=user.gid,
                       extra_groups=[], env={}, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL, check=False)
        time.sleep(min(0.01 * attempt, 0.1))
    return len(_processes_of(user.uid))


_subreaper = False


def _become_subreaper():
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


def _reap_orphans(user):
    # Only the user's zombies: every command of that user has ended (one runs at a time),
    # so none of them is a Popen another thread still waits for.
    for pid, parent in _processes_of(user.uid, state="Z"):
        if parent == os.getpid():
            try:
                os.waitpid(pid, os.WNOHANG)
            except ChildProcessError:
                pass


_user_locks = {}
_user_locks_lock = threading.Lock()


def _user_lock(user):
    with _user_locks_lock:
        return _user_locks.setdefault(user.uid, threading.Lock())


@functools.cache  # the mounts do not change while the grader runs
def _pids_hierarchies():
    """Where a new pids cgroup can go: the cgroup v2 root when its pids controller is
    enabled for children, then cgroup v1's pids hierarchy."""
    v2, v1 = [], []
    try:
        with open("/proc/self/mounts") as f:
            for line in f:
                parts = line.split()
                if len(parts) >= 4 and parts[2] == "cgroup2":
                    v2.append(parts[1])
                elif len(parts) >= 4 and parts[2] == "cgroup" and "pids" in parts[3].split(","):
                    v1.append(parts[1])
    except OSError:
        return ()
    usable = []
    for mount in v2:
        try:
            with open(os.path.join(mount, "cgroup.subtree_control")) as f:
                if "pids" in f.read().split():
                    usable.append(mount)
        except OSError:
            pass
    return tuple(usable + v1)


_cgroup_serial = itertools.count(1)  # next() is atomic: the grader runs jobs on threads
_stale_check = itertools.count(0)  # stale cgroups are looked for once per grader


def _remove_stale_cgroups(hierarchy):
    # Left by a grader that was killed: the empty cgroups of processes that are gone.
    try:
        names = os.listdir(hierarchy)
    except OSError:
        return
    for name in names:
        parts = name.split("-")
        if len(parts) != 4 or parts[:2] != ["boxes", "sandbox"] or not parts[2].isdigit():
            continue
        try:
            os.kill(int(parts[2]), 0)
            continue  # its grader still runs
        except ProcessLookupError:
            pass
        except OSError:
            continue
        try:
            os.rmdir(os.path.join(hierarchy, name))
        except OSError:
            pass  # tasks still in it


def _make_pids_cgroup(limit):
    """As root: a new cgroup of at most `limit` tasks; its folder, or None where no pids
    controller can be written."""
    for hierarchy in _pids_hierarchies():
        if next(_stale_check) == 0:
            _remove_stale_cgroups(hierarchy)
        serial = next(_cgroup_serial)
        folder = os.path.join(hierarchy, f"boxes-sandbox-{os.getpid()}-{serial}")
        try:
            os.mkdir(folder)
        except OSError:
            continue
        try:
            with open(os.path.join(folder, "pids.max"), "w") as f:
                f.write(str(limit))
            return folder
        except OSError:
            _remove_cgroup(folder)
    return None


def _remove_cgroup(folder):
    # Its tasks were killed with the sandbox; the kernel may take a moment to reap them.
    for _ in range(50):
        try:
            os.rmdir(folder)
            return
        except FileNotFoundError:
            return
        except OSError:
            time.sleep(0.05)


_warned_no_pids = False


def _process_limit(limits):
    """(cgroup folder or None, RLIMIT_NPROC value or None) for a run."""
    global _warned_no_pids
    if os.geteuid() != 0:
        return None, _user_tasks(os.getuid()) + limits.processes
    folder = _make_pids_cgroup(limits.processes)
    if folder is None and not _warned_no_pids:
        _warned_no_pids = True
        print("sandbox: WARNING: running as root without a writable pids cgroup: the number "
              "of processes is not limited", file=sys.stderr)
    return folder, None


def _set_limits(limits, cgroup=None, nproc=None, user=None):
    def apply():
        if cgroup:  # first: every process the command starts stays in it
            with open(os.path.join(cgroup, "cgroup.procs"), "w") as f:
                f.write(str(os.getpid()))
        if nproc is not None:
            resource.setrlimit(resource.RLIMIT_NPROC, (nproc, nproc))
        cpu = limits.cpu_seconds()
        file_bytes = int((limits.file_mb or limits.output_mb) * (1 << 20))
        resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 1))  # SIGXCPU, then SIGKILL
        resource.setrlimit(resource.RLIMIT_AS, (limits.memory_mb << 20,) * 2)
        resource.setrlimit(resource.RLIMIT_FSIZE, (file_bytes,) * 2)  # SIGXFSZ past it
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        os.umask(0o022)  # what a build makes, the tests (another user, maybe) can read
        if user is not None:  # last: the limits above are set while still root
            os.setgroups([])
            os.setgid(user.gid)
            os.setuid(user.uid)
    return apply


def _signal_name(number):
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


def run(cmd, limits, writable=(), cwd=None, isolate=True, keep=1 << 20, env=None, hidden=(),
        readable=(), user=None, scratch=None, outputs=()):
    """Runs cmd under the sandbox and limits; returns a Result. `writable`: the folders the
    command may write (cwd, default the first of them or `scratch`, is one of them when
    isolated); `readable`: the folders it may read besides the system (isolated; nothing
    else of the machine is there); `hidden`: folders of the system it must not read (they
    look empty). `scratch`: a folder the caller made, the command's working folder: when
    isolated a fresh tmpfs of limits.disk_mb there, of which only the files `outputs`
    (paths inside it, made empty here) reach the host; else the folder itself. `user` (a
    User; as root): the command runs as that user; isolated, as root, without `user`: as a
    fresh user id of its own (box_user). The writable folders, `scratch` and `outputs` are
    that user's while it runs (lent, then the caller's again). Without isolation every
    process of `user` is killed when the command ends, and `hidden`, `readable` and
    `writable` are the file permissions' business. Raises Stopped after stop_all()."""
    if _stop.is_set():
        raise Stopped()
    writable = [os.path.abspath(d) for d in writable]
    hidden = [os.path.abspath(d) for d in hidden]
    readable = [os.path.abspath(d) for d in readable]
    scratch = scratch and os.path.abspath(scratch)
    outputs = [os.path.abspath(f) for f in outputs]
    cwd = os.path.abspath(cwd or scratch or (writable[0] if writable else os.getcwd()))
    output_bytes = int(limits.output_mb * (1 << 20))
    for f in outputs:
        with open(f, "wb"):
            pass
    if user is not None and os.geteuid() != 0:
        raise ValueError("sandbox: running commands as another user needs root")
    if not isolate:
        if user is not None:
            return _run_as(user, list(cmd), limits, cwd, keep, env, output_bytes,
                           writable + ([scratch] if scratch else []) + outputs)
        return _run_here(list(cmd), limits, cwd, False, keep, env, output_bytes)
    with _box_user(user) as box:
        full = bwrap_prefix(writable or ([] if scratch else [cwd]), cwd, output_bytes, hidden, readable,
                            scratch, limits.disk_mb * (1 << 20), outputs, box) + ["--"]
        full += (become(box) if box else []) + list(cmd)
        with _lent(writable + outputs if box else [], box):
            return _run_here(full, limits, cwd, True, keep, env, output_bytes)


def _run_here(full, limits, cwd, isolate, keep, env, output_bytes):
    """As the grader's user (bubblewrap itself, as root, drops to the box user inside)."""
    cgroup, nproc = _process_limit(limits)
    try:
        result = _run_limited(full, limits, cwd, isolate, keep, env, output_bytes, cgroup, nproc)
    finally:
        if cgroup:
            _remove_cgroup(cgroup)
    if _stop.is_set():  # killed by stop_all: its result is not the command's
        raise Stopped()
    return result


def _run_as(user, full, limits, cwd, keep, env, output_bytes, lent):
    """Without isolation, as root: as `user`, alone (every process of it is killed before
    and after), under RLIMIT_NPROC."""
    _become_subreaper()
    with _user_lock(user), _lent(lent, user):
        kill_user(user)  # nothing of that user runs beside the command
        try:
            result = _run_limited(full, limits, cwd, False, keep, env, output_bytes, None,
                                  _user_tasks(user.uid) + limits.processes, user)
        finally:
            kill_user(user)
            _reap_orphans(user)
    if _stop.is_set():
        raise Stopped()
    return result


BOX_UID_BASE = 2130706432  # 0x7F000000: far above login users, system users and subuid ranges
_BOX_SLOTS = 64  # sandboxed commands of one grader at once
_box_free = list(range(_BOX_SLOTS))
_box_lock = threading.Lock()
_warned_no_setpriv = False


@contextlib.contextmanager
def _box_user(user):
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
def _lent(paths, user):
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


def _run_limited(full, limits, cwd, isolate, keep, env, output_bytes, cgroup, nproc, user=None):
    started = time.monotonic()
    try:
        p = subprocess.Popen(full, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, start_new_session=True, env=env,
                             preexec_fn=_set_limits(limits, cgroup, nproc, user))
    except (OSError, subprocess.SubprocessError) as e:
        return Result("failed", f"failed: cannot start ({e})", 127, b"", str(e).encode(), 0.0)
    with _live_lock:
        _live.add(p)
    if _stop.is_set():  # stop_all ran between Popen and now
        _kill(p)
    try:
        return _collect(p, limits, started, isolate, keep, output_bytes,
                        (lambda: kill_user(user)) if user is not None else (lambda: _killpg(p)))
    except BaseException:  # KeyboardInterrupt, say: the command does not outlive its run
        if p.returncode is None:
            _kill(p)
        raise
    finally:
        with _live_lock:
            _live.discard(p)


PIPE_GRACE = 2.0  # seconds to read what is left in the pipes once the command has ended


def _exited(p):
    """Whether the command's first process has ended, without reaping it: its number stays
    taken, so its process group can still be signalled safely."""
    if p.returncode is not None:
        return True
    try:
        return os.waitid(os.P_PID, p.pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is not None
    except ChildProcessError:
        return True


def _killpg(p):
    try:
        os.killpg(p.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def _collect(p, limits, started, isolate, keep, output_bytes, on_exit):
    """Reads the command's output within the limits; kills it at the first one passed.
    Once its first process has ended, on_exit() kills what it left (a child that still
    holds the pipes would otherwise keep the run going until the time limit)."""
    out, err = bytearray(), bytearray()
    printed, stopped = 0, ""
    sel = selectors.DefaultSelector()
    sel.register(p.stdout, selectors.EVENT_READ, out)
    sel.register(p.stderr, selectors.EVENT_READ, err)
    deadline = started + limits.seconds
    open_pipes = 2
    exited_at = None
    while open_pipes and not stopped:
        now = time.monotonic()
        left = deadline - now
        if left <= 0:
            stopped = "time limit"
            break
        if exited_at is None and _exited(p):
            exited_at = now
            on_exit()
        elif exited_at is not None and now - exited_at > PIPE_GRACE:
            break  # what still holds the pipes escaped the kill: stop reading
        for key, _ in sel.select(timeout=min(left, 0.2)):
            chunk = os.read(key.fd, 1 << 16)
            if not chunk:
                sel.unregister(key.fileobj)
                open_pipes -= 1
                continue
            printed += len(chunk)
            buf = key.data
            if len(buf) < keep:
                buf += chunk[: keep - len(buf)]
            if printed > output_bytes:
                stopped = "output limit"
                break
    if not stopped:
        try:
            p.wait(timeout=max(0.0, deadline - time.monotonic()))
        except subprocess.TimeoutExpired:
            stopped = "time limit"
    if stopped:
        _kill(p)
    sel.close()
    p.stdout.close()
    p.stderr.close()
    seconds = time.monotonic() - started
    return _classify(p.returncode, stopped, isolate, bytes(out), bytes(err), seconds)


def _kill(p):
    try:
        os.killpg(p.pid, signal.SIGKILL)  # bwrap and, through --die-with-parent, the sandbox
    except ProcessLookupError:
        pass
    try:
        p.wait(timeout=10)
    except subprocess.TimeoutExpired:
        p.kill()
        p.wait()


def _classify(code, stopped, isolate, out, err, seconds):
    def result(status, reason):
        return Result(status, reason, code, out, err, seconds)

    if stopped:
        return result(stopped, stopped)
    if code == 0:
        return result("ok", "ok")
    # Killed by a signal: Popen says -N; bubblewrap passes its child's death on as 128 + N.
    signum = -code if code < 0 else (code - 128 if isolate and 128 < code < 160 else 0)
    if any(sign in out[-4096:] + err for sign in MEMORY_SIGNS):
        return result("memory limit", "memory limit")
    if signum == signal.SIGXCPU:
        return result("time limit", "time limit")
    if signum == signal.SIGXFSZ:
        return result("output limit", "output limit")
    if signum:
        return result("crashed", f"crashed: {_signal_name(signum)}")
    return result("failed", f"failed: exit {code}")


def main(argv):
    p = argparse.ArgumentParser(prog="tools/grading/sandbox.sh", description=__doc__.split("\n\n")[0],
                                epilog="\n\n".join(__doc__.split("\n\n")[2:]),
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--time", type=decimal(0, MAX_SECONDS), default=10.0, help="wall-clock seconds (default 10)")
    p.add_argument("--memory", type=integer(1, MAX_MB), default=1024, help="address space in MB per process (default 1024)")
    p.add_argument("--output", type=decimal(0, MAX_MB), default=16.0, help="MB printed, and per file written (default 16)")
    p.add_argument("--processes", type=integer(1, 1 << 20), default=256,
                   help="processes and threads at once (default 256)")
    p.add_argument("--dir", help="the writable working folder (default: a new one in the "
                   "clone's build/sandbox/, kept for its stdout.txt and stderr.txt)")
    p.add_argument("--no-isolation", action="store_true", help="limits only, no bubblewrap (trusted code)")
    p.add_argument("--user", help="with --no-isolation, as root: run as this unprivileged user and kill "
                                  "every process of it afterwards")
    p.add_argument("command", nargs=argparse.REMAINDER)
    args = p.parse_args(argv)
    cmd = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not cmd:
        p.print_usage(sys.stderr)
        print("sandbox: no command given", file=sys.stderr)
        return 2
    if args.time <= 0 or args.memory <= 0 or args.output <= 0 or args.processes <= 0:
        print("sandbox: --time, --memory, --output and --processes must be positive",
              file=sys.stderr)
        return 2
    user = None
    if args.user:
        if not args.no_isolation or os.geteuid() != 0:
            print("sandbox: --user goes with --no-isolation, as root", file=sys.stderr)
            return 2
        try:
            user = grading_user(args.user)
        except ValueError as e:
            print(f"sandbox: {e}", file=sys.stderr)
            return 2
    if args.no_isolation:
        print("sandbox: WARNING: running without isolation (--no-isolation)" +
              (f", as user {user.name}" if user else ""), file=sys.stderr)
    else:
        problem = isolation_problem()
        if problem:
            print(f"sandbox: {problem}; refusing to run untrusted code without isolation "
                  "(--no-isolation to force)", file=sys.stderr)
            return 2
    if args.dir:
        folder = args.dir
        os.makedirs(folder, exist_ok=True)
    else:  # kept for the outputs, so in the clone (build/), never in the shared /tmp
        runs = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                            "build", "sandbox")
        os.makedirs(runs, exist_ok=True)
        folder = tempfile.mkdtemp(prefix="run-", dir=runs)
        print(f"sandbox: the command's folder: {folder}", file=sys.stderr)
    if user:
        os.chown(folder, user.uid, user.gid)
    # The command's own program, when it is a file of the caller's, is shown read-only.
    program = shutil.which(cmd[0]) if os.sep not in cmd[0] else os.path.abspath(cmd[0])
    r = run(cmd, Limits(args.time, args.memory, args.output, processes=args.processes),
            writable=[folder], isolate=not args.no_isolation, keep=int(args.output * (1 << 20)),
            user=user, readable=[program] if program and os.path.isfile(program) else [])
    for name, data in (("stdout.txt", r.stdout), ("stderr.txt", r.stderr)):
        with open(os.path.join(folder, name), "wb") as f:
            f.write(data)
    print(f"sandbox: {r.reason}", flush=True)
    return {"ok": 0, "failed": 1}.get(r.status, 3)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
