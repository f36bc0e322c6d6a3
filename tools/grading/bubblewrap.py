"""The bubblewrap command line of the sandbox (sandbox.py runs it): what of the machine a
command sees (the system read-only and the folders it is given), the namespaces, and as
root the user of its own it becomes (setpriv)."""
import functools
import os
import shutil
import subprocess


def bwrap_program():
    return os.environ.get("BOXES_BWRAP") or shutil.which("bwrap") or ""


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
    # The folders above a bound one (those of the system exist already): bubblewrap would make
    # them 0700, which a user id of the sandbox's own could not pass. They are 0111, passable
    # and nothing else: without root the sandbox runs as the folders' owner, and with 0755 it
    # could list them (the path to the clone in a home) and write into them.
    made = set(SYSTEM_DIRS) | {"/", "/tmp", "/dev", "/proc"}
    for d in [r for r in readable if os.path.exists(r)] + list(writable) + ([scratch] if scratch else []):
        parts = d.strip("/").split("/")[:-1]
        for k in range(1, len(parts) + 1):
            up = "/" + "/".join(parts[:k])
            shown = any(_inside(up, s) for s in SYSTEM_DIRS) and not any(_inside(up, c) for c in covers)
            if up not in made and not shown:
                made.add(up)
                prefix += ["--perms", "0111", "--dir", up]
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
