#!/usr/bin/python3
"""The computer lab (ctest label "lab"): packages installed once by an administrator, every
student an ordinary user with a clone of their own.

usage: python3 -m tests.lab_test WORK_DIR   (as root: it creates two users; skipped, 77, otherwise)

As root, with a root-owned file already at every fixed /tmp path the workbook once used
(FIXED_PATHS), it creates two unprivileged users, gives each a fresh clone of this tree in
their home, configures it once (-O1, as the grader builds), then runs COMMANDS as both users
at the same time (setpriv, a clean environment): the tour of one step and that step's tests
(both users), then grading the clone (the first user) while the second writes a starter kit
and runs the kit's check of that step. Every command must succeed, and after each one the
user owns nothing new in /tmp, /var/tmp or /dev/shm. Where ccache is installed the
administrator first fills the lab's shared compiler cache (docs/instructors.md, "A lab's
compiler cache") from a clone of its own, and the users' builds read it and cannot write it:
their first builds take the administrator's objects. Then, with stand-ins for dpkg-query and npm on
PATH (no network, no install): a missing package names what the administrator runs once;
npm's log goes nowhere shared (the old /tmp log broke the second user); a failing npm shows
its output; Ctrl-C during npm leaves nothing behind. The users and their homes are removed
at the end; at the start, so are those an interrupted run left whose work folder is gone
(each user's comment field names its run's work folder).
"""
import hashlib
import os
import pwd
import re
import resource
import shutil
import signal
import subprocess
import sys
import threading
import time

from tools import ROOT
from tools.grading.kit import tracked_files
from tools.grading.users import processes_of

SKIPPED = 77
STEP = "01"
# The fixed paths the commands once wrote (tools/deps.sh's logs): each gets a root-owned file,
# which an ordinary user can neither replace nor write.
FIXED_PATHS = ["/tmp/boxes-apt.log", "/tmp/boxes-npm.log"]
SHARED_TEMP = ["/tmp", "/var/tmp", "/dev/shm"]
GRADING = os.path.exists(os.path.join(ROOT, "tools", "grading", "grade.py"))  # not in a kit
KIT = "kit"  # the starter kit the second user writes beside their clone, in their home
# -O1, as the grader builds: the users' builds cost less, and what is tested is the same.
# Where ccache is installed the project compiles through it with paths relative to the clone
# (the top CMakeLists.txt), each user into a cache of their own in their home (removed with
# it), reading the lab's shared cache (LAB_CACHE) that the administrator filled.
CCACHE = shutil.which("ccache")
CONFIGURE = ["cmake", "--preset", "release", "-DCMAKE_CXX_FLAGS_RELEASE=-O1 -DNDEBUG"]
# What the administrator builds into the lab's cache: what the users' first commands build.
PRIMED = [next(d for d in sorted(os.listdir(os.path.join(ROOT, "steps"))) if d.startswith(STEP + "_")),
          f"test_step{STEP}"]
LAB_CACHE = "lab-cache"  # in the work folder
# What the users run, in order: (name, command, who, where). One line per command. who:
# "both" at once, or the first or the second user alone; where: the clone, or the kit.
# The grader's build is a second build of the core (in its sandbox, without the cache): the
# first user grades while the second writes a starter kit and runs its check of one step,
# whose build takes the core and the tests from that user's cache.
COMMANDS = [
    ("tour", ["./workbook", "tour", "--steps", STEP], "both", "clone"),
    ("test", ["./workbook", "test", "--steps", STEP], "both", "clone"),
] + ([("grade", ["./workbook", "grade", ".", "--steps", STEP, "--timeout", "20"], "first", "clone"),
      ("kit", ["./workbook", "kit", os.path.join("..", KIT), "--no-pictures"], "second", "clone"),
      ("configure the kit", CONFIGURE, "second", "kit"),
      ("check", ["./workbook", "check", STEP], "second", "kit")] if GRADING else [])

failures = []
lock = threading.Lock()


def check(condition, message):
    with lock:
        print(("ok    " if condition else "FAIL  ") + message, flush=True)
        if not condition:
            failures.append(message)


def user_names(work):
    """Two names of this work folder's own: runs in other trees do not share them."""
    tag = hashlib.sha1(os.path.abspath(work).encode()).hexdigest()[:7]
    return [f"boxes-lab{tag}{c}" for c in "ab"]


COMMENT = "boxes lab test in "  # + the work folder, in the user's comment field


def comment_args(work):
    """useradd's arguments naming the run's work folder (none where ':', which ends the field, is in it)."""
    return ["--comment", COMMENT + work] if ":" not in work else []


def remove_leftovers():
    """Users an interrupted run in another tree left: their work folder is gone."""
    for entry in pwd.getpwall():
        if entry.pw_name.startswith("boxes-lab") and entry.pw_gecos.startswith(COMMENT):
            if not os.path.isdir(entry.pw_gecos[len(COMMENT):]):
                remove_user(entry.pw_name)


def remove_user(name):
    try:
        uid = pwd.getpwnam(name).pw_uid
    except KeyError:
        return
    for pid, _ in processes_of(uid):
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    subprocess.run(["userdel", "-r", name], capture_output=True)


def owned_in_temp(uid):
    """What the user owns at the top of the shared temporary folders."""
    found = set()
    for folder in SHARED_TEMP:
        try:
            names = os.listdir(folder)
        except OSError:
            continue
        for n in names:
            try:
                if os.lstat(os.path.join(folder, n)).st_uid == uid:
                    found.add(os.path.join(folder, n))
            except OSError:
                pass
    return found


class User:
    def __init__(self, name, work):
        subprocess.run(["useradd", "--create-home", "--shell", "/bin/bash", *comment_args(work), name],
                       check=True, capture_output=True)
        self.pw = pwd.getpwnam(name)
        self.name, self.home = name, self.pw.pw_dir
        self.clone = os.path.join(self.home, "boxes")
        self.kit = os.path.join(self.home, KIT)
        self.lab_cache = None

    def env(self, **extra):
        """A login's plain environment: no TMPDIR, nothing of this test's."""
        env = dict(PATH="/usr/local/bin:/usr/bin:/bin", HOME=self.home, USER=self.name,
                   LOGNAME=self.name, LANG="C.UTF-8")
        if CCACHE:  # the user's own cache, and the lab's to read (the /etc/ccache.conf line)
            env.update(CCACHE_DIR=os.path.join(self.home, ".ccache"),
                       CCACHE_TEMPDIR=os.path.join(self.home, ".ccache", "tmp"))
            if self.lab_cache:
                env.update(CCACHE_REMOTE_STORAGE=f"file:{self.lab_cache}|read-only")
        env.update(extra)
        return env

    def popen(self, cmd, cwd=None, **extra):
        return subprocess.Popen(["setpriv", f"--reuid={self.pw.pw_uid}", f"--regid={self.pw.pw_gid}",
                                 "--init-groups", "--"] + cmd, cwd=cwd or self.clone, env=self.env(**extra),
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                start_new_session=True)

    def run(self, cmd, timeout=900, cwd=None, **extra):
        p = self.popen(cmd, cwd=cwd, **extra)
        try:
            out, _ = p.communicate(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            out, _ = p.communicate()
            return 124, out
        return p.returncode, out


def fresh_clone(dest):
    """A fresh clone of this tree as it is on disk (uncommitted edits too)."""
    subprocess.run(["git", "clone", "--quiet", "--no-hardlinks", ROOT, dest], check=True)
    for rel in tracked_files(ROOT):
        path = os.path.join(dest, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        shutil.copy2(os.path.join(ROOT, rel), path)


def make_clone(user):
    """A fresh clone that the user owns."""
    fresh_clone(user.clone)
    subprocess.run(["chown", "-R", f"{user.name}:{user.name}", user.clone], check=True)


def fill_lab_cache(work):
    """The administrator's part (docs/instructors.md, "A lab's compiler cache"): in a clone of
    their own, builds what the students' first commands build, each object also written to
    the lab's cache (reshared when the administrator's own cache already has it); the cache's
    files readable by all, writable by root only. Returns its folder."""
    cache, clone = os.path.join(work, LAB_CACHE), os.path.join(work, "administrator")
    shutil.rmtree(clone, ignore_errors=True)
    shutil.rmtree(cache, ignore_errors=True)
    os.makedirs(cache, mode=0o755)
    fresh_clone(clone)
    env = dict(os.environ, CCACHE_REMOTE_STORAGE=f"file:{cache}|umask=022", CCACHE_RESHARE="1")
    started = time.monotonic()
    r = subprocess.run(CONFIGURE, cwd=clone, env=env, capture_output=True, text=True)
    if r.returncode == 0:
        r = subprocess.run(["cmake", "--build", "--preset", "release", "--target", *PRIMED], cwd=clone,
                           env=env, capture_output=True, text=True)
    check(r.returncode == 0, f"the administrator fills the lab's cache ({time.monotonic() - started:.0f} s; "
          f"{tail(r.stdout + r.stderr, 5)})")
    shutil.rmtree(clone, ignore_errors=True)
    return cache


def remote_hits(user):
    """How many of the user's compiles came from the lab's cache (ccache's statistics)."""
    rc, out = user.run(["ccache", "--print-stats"])
    stats = dict(line.split("\t", 1) for line in out.splitlines() if "\t" in line)
    return int(stats.get("remote_storage_hit", "0"))


def tail(text, n=30):
    return "\n".join(text.splitlines()[-n:])


def scenario(user, first):
    """Configure once, then COMMANDS in order (those of both users and this user's own);
    each succeeds and leaves nothing in /tmp."""
    before = owned_in_temp(user.pw.pw_uid)
    check(not before, f"{user.name}: owns nothing in {', '.join(SHARED_TEMP)} before: {sorted(before)}")
    rc, out = user.run(CONFIGURE)
    check(rc == 0, f"{user.name}: configures its clone ({tail(out, 5)})")
    for name, cmd, who, where in COMMANDS:
        if who != "both" and (who == "first") != first:
            continue
        started = time.monotonic()
        rc, out = user.run(cmd, cwd=user.kit if where == "kit" else user.clone)
        left = owned_in_temp(user.pw.pw_uid) - before
        seconds = time.monotonic() - started
        if rc != 0:
            print(f"--- {user.name}: {' '.join(cmd)}\n{tail(out)}", flush=True)
        check(rc == 0, f"{user.name}: {' '.join(cmd)} succeeds as an ordinary user ({seconds:.0f} s, exit {rc})")
        check(not left, f"{user.name}: {name} leaves nothing of its own in the shared temporary folders: {sorted(left)}")
        if name == "tour":
            check(os.path.exists(os.path.join(user.clone, "out", "index.html")),
                  f"{user.name}: the tour wrote out/index.html in its clone")
            if user.lab_cache:
                hits = remote_hits(user)
                check(hits > 0, f"{user.name}: the first build took {hits} objects from the lab's cache")
                rc, _ = user.run(["touch", os.path.join(user.lab_cache, "planted")])
                check(rc != 0, f"{user.name}: cannot write into the lab's cache")
        if name == "check":
            check(re.search(r"^  total\s+0/\d+\s+points", out, re.M) is not None and
                  f"Next: exercise {int(STEP)}.1:" in out,
                  f"{user.name}: the kit's check of step {STEP}: 0 points, exercise {int(STEP)}.1 next")


def write_script(path, text, owner):
    with open(path, "w") as f:
        f.write(text)
    os.chmod(path, 0o755)
    os.chown(path, owner.pw.pw_uid, owner.pw.pw_gid)


def deps_scenario(user):
    """tools/deps.sh as an ordinary user with stand-ins for dpkg-query (a package missing on
    request) and npm (succeeds, fails or hangs on request)."""
    fake = os.path.join(user.home, "fake-bin")
    os.makedirs(fake, exist_ok=True)
    os.chown(fake, user.pw.pw_uid, user.pw.pw_gid)
    write_script(os.path.join(fake, "dpkg-query"),
                 '#!/bin/sh\nfor p; do :; done\n'
                 'case " $FAKE_MISSING " in *" $p "*) exit 1 ;; esac\n'
                 "printf 'install ok installed'\n", user)
    write_script(os.path.join(fake, "npm"),
                 '#!/bin/sh\necho "npm stand-in: $*"\ntouch "$HOME/npm-ran"\n'
                 '[ -n "$FAKE_NPM_FAIL" ] && { echo "npm stand-in: E404 no such package"; exit 1; }\n'
                 '[ -n "$FAKE_NPM_SLOW" ] && { mkdir -p "$HOME/npm-started"; sleep 60; }\nexit 0\n', user)
    path = f"{fake}:/usr/local/bin:/usr/bin:/bin"
    uid = user.pw.pw_uid
    deps = ["tools/deps.sh"]

    rc, out = user.run(deps + ["build", "test"], PATH=path, FAKE_MISSING="libglm-dev xvfb")
    check(rc == 1 and "sudo tools/deps.sh build test" in out and "sudo tools/deps.sh all" in out
          and "apt-get install -y --no-install-recommends libglm-dev xvfb" in out,
          f"deps.sh, packages missing: names what the administrator runs once and the packages ({tail(out, 6)})")
    check(not owned_in_temp(uid), "deps.sh, packages missing: nothing left in /tmp")

    shutil.rmtree(os.path.join(user.clone, "slides", "node_modules"), ignore_errors=True)
    rc, out = user.run(deps + ["slides"], PATH=path)
    ran = os.path.exists(os.path.join(user.home, "npm-ran"))
    check(rc == 0 and ran and "failed" not in out,
          f"deps.sh slides, npm succeeds, root-owned {FIXED_PATHS[1]} there: it succeeds ({tail(out, 4)})")
    check(not owned_in_temp(uid), "deps.sh slides: npm's log left nothing in /tmp")

    rc, out = user.run(deps + ["slides"], PATH=path, FAKE_NPM_FAIL="1")
    check(rc == 1 and "npm ci in slides/ failed" in out and "E404 no such package" in out,
          f"deps.sh slides, npm fails: exit 1 with npm's last lines ({tail(out, 4)})")
    check(not owned_in_temp(uid), "deps.sh slides, npm fails: its log is gone from /tmp")

    # Ctrl-C while npm runs: SIGINT to the whole foreground process group, as a terminal sends it.
    started = os.path.join(user.home, "npm-started")
    shutil.rmtree(started, ignore_errors=True)
    p = user.popen(deps + ["slides"], PATH=path, FAKE_NPM_SLOW="1")
    deadline = time.monotonic() + 60
    while not os.path.exists(started) and time.monotonic() < deadline and p.poll() is None:
        time.sleep(0.1)
    during = owned_in_temp(uid)
    os.killpg(p.pid, signal.SIGINT)
    try:
        p.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
    check(os.path.exists(started) and during, f"deps.sh slides, Ctrl-C: npm was running, its log in {sorted(during)}")
    check(p.returncode != 0 and not owned_in_temp(uid),
          f"deps.sh slides, Ctrl-C: it stops (exit {p.returncode}) and leaves nothing in /tmp")


def main():
    if len(sys.argv) != 2:
        print(__doc__.split("\n\n")[1], file=sys.stderr)
        return 2
    work = os.path.abspath(sys.argv[1])
    if os.geteuid() != 0:
        print("SKIP: creating the lab's users needs root")
        return SKIPPED
    for tool in ("useradd", "userdel", "setpriv"):
        if not shutil.which(tool):
            print(f"FAIL: {tool} is missing (util-linux, passwd)")
            return 1
    names = user_names(work)
    stale = user_names(os.path.join(work, "gone"))[0]
    placed = []
    users = []
    try:
        for path in FIXED_PATHS:
            if not os.path.exists(path):
                with open(path, "w") as f:
                    f.write("root's, from an earlier run\n")
                os.chmod(path, 0o644)
                placed.append(path)
            check(os.lstat(path).st_uid == 0, f"{path} is root's: an ordinary user cannot write it")
        cache = fill_lab_cache(work) if CCACHE else None
        # A user as an interrupted run leaves it, its work folder removed since: it goes.
        planted = bool(comment_args(work))
        if planted:
            subprocess.run(["useradd", "--create-home", *comment_args(os.path.join(work, "gone")), stale],
                           check=True, capture_output=True)
        stale_home = pwd.getpwnam(stale).pw_dir if planted else None
        remove_leftovers()
        if planted:
            check(stale not in {e.pw_name for e in pwd.getpwall()} and not os.path.exists(stale_home),
                  "a user left by an interrupted run whose work folder is gone is removed, with its home")
        for name in names:
            remove_user(name)  # a leftover of an interrupted run
            users.append(User(name, work))
            users[-1].lab_cache = cache
            make_clone(users[-1])
        threads = [threading.Thread(target=scenario, args=(u, u is users[0])) for u in users]
        started = time.monotonic()
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        cpu = resource.getrusage(resource.RUSAGE_CHILDREN)
        print(f"both users: {time.monotonic() - started:.0f} s, {cpu.ru_utime + cpu.ru_stime:.0f} s of CPU",
              flush=True)
        deps_scenario(users[0])
    finally:
        for name in names + [stale]:
            remove_user(name)
        for path in placed:
            os.remove(path)
    print(f"{len(failures)} failed" if failures else "all passed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
