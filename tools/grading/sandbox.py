"""Runs one untrusted command isolated and limited: the grader's student builds and test
runs (box.py imports this module), and tools/grading/sandbox.sh on the command line. Its
parts: bubblewrap.py (the command line: what the command sees), users.py (the users it
runs as), cgroups.py (the CPUs to use, the pids cgroup); here the run and its limits.

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
every thread still stops, or as given: Limits.cpu), address space per process, the size of any file written, and
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
import math
import os
import resource
import selectors
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass

from . import ROOT
from .bubblewrap import become, bwrap_prefix, bwrap_program
from .cgroups import make_pids_cgroup, remove_cgroup, usable_cpus
from .strict_numbers import MAX_MB, MAX_SECONDS, decimal, integer
from .users import box_user, become_subreaper, grading_user, kill_user, lent, reap_orphans, user_lock, user_tasks


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
    cpu: float = 0.0  # CPU seconds of each process; 0: the wall time times the cores

    def cpu_seconds(self):
        if self.cpu > 0:
            return max(1, math.ceil(self.cpu))
        return int(self.seconds * usable_cpus()) + 1


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


_warned_no_pids = False


def _process_limit(limits):
    """(cgroup folder or None, RLIMIT_NPROC value or None) for a run."""
    global _warned_no_pids
    if os.geteuid() != 0:
        return None, user_tasks(os.getuid()) + limits.processes
    folder = make_pids_cgroup(limits.processes)
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
        readable=(), user=None, scratch=None, outputs=(), pass_fds=()):
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
    `writable` are the file permissions' business. `pass_fds`: file descriptors the command
    inherits (the judge's pipes); they are the command's: this process closes its copies as
    soon as the command started, or when run returns or raises without starting it. Raises
    Stopped after stop_all()."""
    fds = list(pass_fds)  # emptied once closed: each is closed exactly once
    try:
        return _run(cmd, limits, writable, cwd, isolate, keep, env, hidden, readable, user, scratch,
                    outputs, fds)
    finally:
        _close_fds(fds)


def _close_fds(fds):
    """Closes the descriptors of the list `fds` and empties it."""
    for fd in fds:
        try:
            os.close(fd)
        except OSError:
            pass
    fds.clear()


def _run(cmd, limits, writable, cwd, isolate, keep, env, hidden, readable, user, scratch, outputs, fds):
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
                           writable + ([scratch] if scratch else []) + outputs, fds)
        return _run_here(list(cmd), limits, cwd, False, keep, env, output_bytes, fds)
    with box_user(user) as box:
        full = bwrap_prefix(writable or ([] if scratch else [cwd]), cwd, output_bytes, hidden, readable,
                            scratch, limits.disk_mb * (1 << 20), outputs, box) + ["--"]
        full += (become(box) if box else []) + list(cmd)
        with lent(writable + outputs if box else [], box):
            return _run_here(full, limits, cwd, True, keep, env, output_bytes, fds)


def _run_here(full, limits, cwd, isolate, keep, env, output_bytes, fds):
    """As the grader's user (bubblewrap itself, as root, drops to the box user inside)."""
    cgroup, nproc = _process_limit(limits)
    try:
        result = _run_limited(full, limits, cwd, isolate, keep, env, output_bytes, cgroup, nproc,
                              pass_fds=fds)
    finally:
        if cgroup:
            remove_cgroup(cgroup)
    if _stop.is_set():  # killed by stop_all: its result is not the command's
        raise Stopped()
    return result


def _run_as(user, full, limits, cwd, keep, env, output_bytes, lend, fds):
    """Without isolation, as root: as `user`, alone (every process of it is killed before
    and after), under RLIMIT_NPROC."""
    become_subreaper()
    with user_lock(user), lent(lend, user):
        kill_user(user)  # nothing of that user runs beside the command
        try:
            result = _run_limited(full, limits, cwd, False, keep, env, output_bytes, None,
                                  user_tasks(user.uid) + limits.processes, user, fds)
        finally:
            kill_user(user)
            reap_orphans(user)
    if _stop.is_set():
        raise Stopped()
    return result


def _run_limited(full, limits, cwd, isolate, keep, env, output_bytes, cgroup, nproc, user=None,
                 pass_fds=None):
    started = time.monotonic()
    try:
        p = subprocess.Popen(full, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, start_new_session=True, env=env,
                             preexec_fn=_set_limits(limits, cgroup, nproc, user),
                             pass_fds=tuple(pass_fds or ()))
    except (OSError, subprocess.SubprocessError) as e:
        return Result("failed", f"failed: cannot start ({e})", 127, b"", str(e).encode(), 0.0)
    finally:
        if pass_fds:
            _close_fds(pass_fds)  # the command's now (its peer sees the end when it ends)
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
        runs = os.path.join(ROOT, "build", "sandbox")
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
