"""The cgroups the sandbox reads and makes: the CPUs this process may use (its affinity cut
to the cgroup's CPU quota), and a pids cgroup per command as root (the kernel does not
apply RLIMIT_NPROC to root)."""
import functools
import itertools
import math
import os
import time


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


def make_pids_cgroup(limit):
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
            remove_cgroup(folder)
    return None


def remove_cgroup(folder):
    # Its tasks were killed with the sandbox; the kernel may take a moment to reap them.
    for _ in range(50):
        try:
            os.rmdir(folder)
            return
        except FileNotFoundError:
            return
        except OSError:
            time.sleep(0.05)
