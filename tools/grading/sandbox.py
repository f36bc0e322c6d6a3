"""Runs one untrusted command isolated and limited: the grader's student builds and test
runs (grade.py imports this module), and tools/grading/sandbox.sh on the command line.

usage: tools/grading/sandbox.sh [--time S] [--memory MB] [--output MB] [--processes N]
                                [--dir DIR] [--no-isolation] -- COMMAND [ARGS...]

Isolation (bubblewrap): the whole system read-only, DIR (default: a fresh temporary folder)
the only writable place and the working directory, a private /tmp of at most the output
limit, no network (an own, empty network namespace), an own PID namespace, no capabilities
and no further user namespaces (even when the grader runs as root), killed with its parent.
Limits (setrlimit, inherited by every process the command starts): wall-clock seconds (the
whole run), CPU seconds (per process: the wall time times the cores, so a busy loop in
every thread still stops), address space per process, the size of any file written, and
the bytes the command prints on stdout and stderr together. The number of processes and
threads (a fork bomb): as root a pids cgroup of its own (the kernel does not apply
RLIMIT_NPROC to root), else RLIMIT_NPROC above the user's current count.

On the command line the command's stdout and stderr go to DIR/stdout.txt and
DIR/stderr.txt (their first bytes, up to the output limit) and one line
"sandbox: RESULT" goes to stdout: ok | failed: exit N | time limit | memory limit |
output limit | crashed: SIGNAME. Exit status: 0 ok, 1 failed, 3 limit or crash, 2 usage
or refused (bubblewrap cannot create namespaces here and no --no-isolation).
Environment: BOXES_BWRAP names the bubblewrap program (default: bwrap on PATH).
"""
import argparse
import functools
import itertools
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

    def cpu_seconds(self):
        return int(self.seconds * (os.cpu_count() or 1)) + 1


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
    """None when bubblewrap can isolate here, else one line saying why not."""
    bwrap = bwrap_program()
    if not bwrap:
        return "bubblewrap is not installed (tools/deps.sh grade installs it)"
    try:
        r = subprocess.run([bwrap] + _namespaces() + ["--ro-bind", "/", "/", "true"],
                           capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired) as e:
        return f"bubblewrap ({bwrap}) does not run: {e}"
    if r.returncode != 0:
        first = (r.stderr.strip().splitlines() or [f"exit {r.returncode}"])[0]
        return f"bubblewrap cannot create namespaces here ({first})"
    return None


def _namespaces():
    # An own user namespace as "nobody" with no capabilities: root outside gets no power
    # inside (no remounting the read-only system, no raising the limits).
    return ["--unshare-all", "--unshare-user", "--uid", "65534", "--gid", "65534",
            "--cap-drop", "ALL", "--disable-userns", "--die-with-parent", "--new-session"]


def bwrap_prefix(writable, cwd, tmp_bytes, hidden=(), readable=()):
    """bubblewrap arguments: the system read-only, `hidden` folders replaced by empty ones,
    `readable` folders (inside hidden ones) shown again read-only, `writable` folders
    read-write, a private /tmp of tmp_bytes, /dev and /proc of the sandbox's own."""
    prefix = [bwrap_program(), "--ro-bind", "/", "/", "--dev", "/dev", "--proc", "/proc"]
    covers = []
    for d in hidden:
        inside_another = any(d != h and d.startswith(h.rstrip("/") + "/") for h in list(hidden) + ["/tmp"])
        if os.path.isdir(d) and d not in ("/", "/tmp") and not inside_another:
            covers.append(d)
            prefix += ["--tmpfs", d]
    prefix += ["--size", str(int(tmp_bytes)), "--tmpfs", "/tmp"]
    for d in readable:
        if os.path.exists(d):
            prefix += ["--ro-bind", d, d]
    for d in writable:
        prefix += ["--bind", d, d]
    for d in covers:  # the empty covers stay read-only (after the binds made their mount points)
        prefix += ["--remount-ro", d]
    return prefix + ["--chdir", cwd] + _namespaces()


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


def _set_limits(limits, cgroup=None, nproc=None):
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
    return apply


def _signal_name(number):
    try:
        return signal.Signals(number).name
    except ValueError:
        return f"signal {number}"


def run(cmd, limits, writable=(), cwd=None, isolate=True, keep=1 << 20, env=None, hidden=(),
        readable=()):
    """Runs cmd under the sandbox and limits; returns a Result. `writable`: the folders the
    command may write (cwd, default the first of them, is one of them when isolated);
    `hidden`: folders it must not read (they look empty), `readable`: folders inside those
    it reads after all. Raises Stopped after stop_all()."""
    if _stop.is_set():
        raise Stopped()
    writable = [os.path.abspath(d) for d in writable]
    hidden = [os.path.abspath(d) for d in hidden]
    readable = [os.path.abspath(d) for d in readable]
    cwd = os.path.abspath(cwd or (writable[0] if writable else os.getcwd()))
    output_bytes = int(limits.output_mb * (1 << 20))
    full = list(cmd)
    if isolate:
        full = bwrap_prefix(writable or [cwd], cwd, output_bytes, hidden, readable) + ["--"] + full
    cgroup, nproc = _process_limit(limits)
    try:
        result = _run_limited(full, limits, cwd, isolate, keep, env, output_bytes, cgroup, nproc)
    finally:
        if cgroup:
            _remove_cgroup(cgroup)
    if _stop.is_set():  # killed by stop_all: its result is not the command's
        raise Stopped()
    return result


def _run_limited(full, limits, cwd, isolate, keep, env, output_bytes, cgroup, nproc):
    started = time.monotonic()
    try:
        p = subprocess.Popen(full, cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, start_new_session=True, env=env,
                             preexec_fn=_set_limits(limits, cgroup, nproc))
    except (OSError, subprocess.SubprocessError) as e:
        return Result("failed", f"failed: cannot start ({e})", 127, b"", str(e).encode(), 0.0)
    with _live_lock:
        _live.add(p)
    if _stop.is_set():  # stop_all ran between Popen and now
        _kill(p)
    try:
        return _collect(p, limits, started, isolate, keep, output_bytes)
    except BaseException:  # KeyboardInterrupt, say: the command does not outlive its run
        if p.returncode is None:
            _kill(p)
        raise
    finally:
        with _live_lock:
            _live.discard(p)


def _collect(p, limits, started, isolate, keep, output_bytes):
    """Reads the command's output within the limits; kills it at the first one passed."""
    out, err = bytearray(), bytearray()
    printed, stopped = 0, ""
    sel = selectors.DefaultSelector()
    sel.register(p.stdout, selectors.EVENT_READ, out)
    sel.register(p.stderr, selectors.EVENT_READ, err)
    deadline = started + limits.seconds
    open_pipes = 2
    while open_pipes and not stopped:
        left = deadline - time.monotonic()
        if left <= 0:
            stopped = "time limit"
            break
        for key, _ in sel.select(timeout=min(left, 1.0)):
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
    p.add_argument("--time", type=float, default=10.0, help="wall-clock seconds (default 10)")
    p.add_argument("--memory", type=int, default=1024, help="address space in MB per process (default 1024)")
    p.add_argument("--output", type=float, default=16.0, help="MB printed, and per file written (default 16)")
    p.add_argument("--processes", type=int, default=256,
                   help="processes and threads at once (default 256)")
    p.add_argument("--dir", help="the writable working folder (default: a new temporary one)")
    p.add_argument("--no-isolation", action="store_true", help="limits only, no bubblewrap (trusted code)")
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
    if args.no_isolation:
        print("sandbox: WARNING: running without isolation (--no-isolation)", file=sys.stderr)
    else:
        problem = isolation_problem()
        if problem:
            print(f"sandbox: {problem}; refusing to run untrusted code without isolation "
                  "(--no-isolation to force)", file=sys.stderr)
            return 2
    folder = args.dir or tempfile.mkdtemp(prefix="boxes-sandbox-")
    os.makedirs(folder, exist_ok=True)
    r = run(cmd, Limits(args.time, args.memory, args.output, processes=args.processes),
            writable=[folder],
            isolate=not args.no_isolation, keep=int(args.output * (1 << 20)))
    for name, data in (("stdout.txt", r.stdout), ("stderr.txt", r.stderr)):
        with open(os.path.join(folder, name), "wb") as f:
            f.write(data)
    print(f"sandbox: {r.reason}", flush=True)
    return {"ok": 0, "failed": 1}.get(r.status, 3)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
