"""Unit tests of tools/grading/sandbox.py: how a run's end becomes its reason, the
bubblewrap command line, the limits, and stopping every run."""
import os
import signal
import tempfile
import threading
import time
import unittest
from unittest import mock
from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools.grading import bubblewrap, cgroups, sandbox, users
from tools.grading.sandbox import Limits, _classify
from tools.grading.submissions import write_files


def reason(code, stopped="", isolate=True, out=b"", err=b""):
    r = _classify(code, stopped, isolate, out, err, 1.5)
    return r.status, r.reason


class Classify(unittest.TestCase):
    def test_exit_codes(self):
        self.assertEqual(reason(0), ("ok", "ok"))
        self.assertEqual(reason(3), ("failed", "failed: exit 3"))

    def test_a_limit_the_sandbox_stopped_wins(self):
        self.assertEqual(reason(-9, "time limit"), ("time limit", "time limit"))
        self.assertEqual(reason(0, "output limit"), ("output limit", "output limit"))

    def test_signals_directly_and_through_bubblewrap(self):
        self.assertEqual(reason(-signal.SIGSEGV), ("crashed", "crashed: SIGSEGV"))
        self.assertEqual(reason(128 + signal.SIGABRT), ("crashed", "crashed: SIGABRT"))
        # Without bubblewrap 128 + N is an ordinary exit status.
        self.assertEqual(reason(128 + signal.SIGABRT, isolate=False), ("failed", "failed: exit 134"))

    def test_the_cpu_and_file_size_limits(self):
        self.assertEqual(reason(-signal.SIGXCPU), ("time limit", "time limit"))
        self.assertEqual(reason(128 + signal.SIGXFSZ), ("output limit", "output limit"))

    def test_a_refused_allocation_is_the_memory_limit(self):
        self.assertEqual(reason(-signal.SIGABRT, err=b"terminate called ... std::bad_alloc\n"),
                         ("memory limit", "memory limit"))
        self.assertEqual(reason(1, out=b"x" * 10000 + b"MemoryError"), ("memory limit", "memory limit"))

    def test_the_result_keeps_the_output(self):
        r = _classify(0, "", True, b"out", b"err", 2.5)
        self.assertEqual((r.stdout, r.stderr, r.seconds, r.ok), (b"out", b"err", 2.5, True))


def mounts(prefix):
    """[(option, destination)] of the mounts a bubblewrap prefix makes."""
    found = []
    for i, arg in enumerate(prefix):
        if arg in ("--ro-bind", "--bind"):
            found.append((arg, prefix[i + 2]))
        elif arg in ("--tmpfs", "--dir", "--symlink", "--dev", "--proc"):
            found.append((arg, prefix[i + 2] if arg == "--symlink" else prefix[i + 1]))
    return found


class BubblewrapPrefix(unittest.TestCase):
    def test_only_the_system_and_the_given_folders_are_there(self):
        home = os.path.expanduser("~")
        work = os.path.join(home, "boxes-test-no-such-folder", "w0", "build")
        data = "/usr/share/doc"  # a folder the test program reads, inside the system
        prefix = bubblewrap.bwrap_prefix([work], work, 1 << 20, hidden=[home, "/usr/share"],
                                      readable=[data])
        text = " ".join(prefix)
        bound = {dest for option, dest in mounts(prefix) if option in ("--ro-bind", "--bind")}
        self.assertEqual(bound, set(bubblewrap.SYSTEM_DIRS) | {work, data} |
                         {d for d in bubblewrap.SYSTEM_LINKS if os.path.isdir(d) and not os.path.islink(d)})
        self.assertNotIn("--ro-bind / /", text)  # not the whole machine, covered in places
        self.assertNotIn(f"--tmpfs {home}", text)  # absent, nothing to cover
        self.assertIn(f"--bind {work} {work}", text)
        self.assertEqual(prefix[prefix.index("--chdir") + 1], work)
        # The folders above the writable one can be passed (not 0700, which a user of the
        # sandbox's own could not pass), not listed or written (not 0755, which the folders'
        # owner, the grader without root, could).
        for up in (home, os.path.dirname(os.path.dirname(work))):
            self.assertIn(f"--perms 0111 --dir {up}", text)
        # A hidden folder the system shows is covered, a readable one inside it shown again.
        self.assertIn("--tmpfs /usr/share", text)
        self.assertLess(prefix.index("/usr/share"), prefix.index(data))
        self.assertLess(prefix.index(data), prefix.index("--remount-ro"))
        self.assertIn(f"--size {1 << 20} --perms 1777 --tmpfs /tmp", text)
        self.assertIn(f"--size {1 << 20} --perms 1777 --tmpfs /dev/shm", text)
        for flag in ("--unshare-all", "--unshare-user", "--cap-drop", "--die-with-parent", "--disable-userns"):
            self.assertIn(flag, prefix)

    def test_a_scratch_folder_is_a_sized_tmpfs_with_its_outputs_bound(self):
        scratch, result = "/w/case", "/w/case/result.xml"
        prefix = bubblewrap.bwrap_prefix([], scratch, 1 << 20, scratch=scratch, scratch_bytes=3 << 20,
                                      outputs=[result])
        text = " ".join(prefix)
        self.assertIn(f"--size {3 << 20} --perms 1777 --tmpfs {scratch}", text)
        self.assertIn(f"--bind {result} {result}", text)
        self.assertLess(text.index(f"--tmpfs {scratch}"), text.index(f"--bind {result}"))
        self.assertNotIn(f"--bind {scratch} ", text)  # nothing of the host folder but the result

    def test_as_root_the_command_becomes_a_user_of_its_own(self):
        user = users.User("uid 2130706500", 2130706500, 2130706500)
        prefix = bubblewrap.bwrap_prefix(["/w"], "/w", 1 << 20, user=user)
        self.assertNotIn("--unshare-user", prefix)  # its id outside is the user's, not root's
        self.assertNotIn("--unshare-all", prefix)
        for flag in ("--unshare-pid", "--unshare-net", "--unshare-ipc", "--die-with-parent"):
            self.assertIn(flag, prefix)
        kept = [prefix[i + 1] for i, a in enumerate(prefix) if a == "--cap-add"]
        self.assertEqual(set(kept), {"CAP_SETUID", "CAP_SETGID", "CAP_SETPCAP", "CAP_DAC_OVERRIDE"})
        become = bubblewrap.become(user)
        self.assertTrue(become[0].endswith("setpriv"))
        for flag in ("--reuid=2130706500", "--regid=2130706500", "--clear-groups", "--inh-caps=-all",
                     "--bounding-set=-all", "--no-new-privs"):
            self.assertIn(flag, become)


class OlderBubblewrap(unittest.TestCase):
    def test_options_it_lacks_are_left_out(self):
        with mock.patch.object(bubblewrap, "bwrap_has", lambda option: False):  # Ubuntu 22.04's 0.6
            prefix = bubblewrap.bwrap_prefix(["/w"], "/w", 1 << 20)
        self.assertNotIn("--disable-userns", prefix)
        self.assertNotIn("--size", prefix)
        self.assertIn("--unshare-user", prefix)
        self.assertEqual(prefix[prefix.index("--tmpfs") + 1], "/tmp")


class CpuQuota(unittest.TestCase):
    def layout(self, cgroup_lines, mounts, files):
        root = write_files(tempfile.mkdtemp(), files)
        with open(os.path.join(root, "cgroup"), "w") as f:
            f.write(cgroup_lines)
        with open(os.path.join(root, "mounts"), "w") as f:
            f.write(mounts.replace("ROOT", root))
        return os.path.join(root, "cgroup"), os.path.join(root, "mounts")

    def test_cgroup_v2_in_a_container_and_on_a_host(self):
        # A container's namespace shows its cgroup as /: the quota is at the mount's root.
        args = self.layout("0::/\n", "cgroup2 ROOT/fs cgroup2 rw 0 0\n", {"fs/cpu.max": "50000 100000\n"})
        self.assertEqual(cgroups.cgroup_cpu_quota(*args), 0.5)
        # On a host: the tightest of the cgroup and its parents.
        args = self.layout("0::/a/b\n", "cgroup2 ROOT/fs cgroup2 rw 0 0\n",
                           {"fs/cpu.max": "max 100000\n", "fs/a/cpu.max": "150000 100000\n",
                            "fs/a/b/cpu.max": "max 100000\n"})
        self.assertEqual(cgroups.cgroup_cpu_quota(*args), 1.5)

    def test_cgroup_v1_and_none(self):
        args = self.layout("4:cpu,cpuacct:/docker/abc\n", "cgroup ROOT/cpu cgroup rw,cpu,cpuacct 0 0\n",
                           {"cpu/cpu.cfs_quota_us": "200000\n", "cpu/cpu.cfs_period_us": "100000\n"})
        self.assertEqual(cgroups.cgroup_cpu_quota(*args), 2.0)  # the path is not there: the mount's root
        args = self.layout("4:cpu,cpuacct:/\n", "cgroup ROOT/cpu cgroup rw,cpu,cpuacct 0 0\n",
                           {"cpu/cpu.cfs_quota_us": "-1\n", "cpu/cpu.cfs_period_us": "100000\n"})
        self.assertIsNone(cgroups.cgroup_cpu_quota(*args))

    def test_usable_cpus(self):
        self.assertTrue(1 <= cgroups.usable_cpus() <= (os.cpu_count() or 1))


class LimitsAndRuns(unittest.TestCase):
    def test_cpu_seconds_cover_every_core(self):
        self.assertEqual(Limits(seconds=10).cpu_seconds(), 10 * cgroups.usable_cpus() + 1)

    def test_a_run_without_isolation(self):
        r = sandbox.run(["sh", "-c", "echo hi; echo oops >&2; exit 4"], Limits(seconds=10), isolate=False)
        self.assertEqual((r.status, r.reason, r.stdout, r.stderr), ("failed", "failed: exit 4", b"hi\n", b"oops\n"))

    @unittest.skipUnless(os.geteuid() == 0, "running as another user needs root")
    def test_as_root_the_command_is_another_user_and_its_folder_is_lent(self):
        folder = tempfile.mkdtemp()
        script = "id -u; echo made > made.txt"
        runs = [(dict(isolate=False, user=users.grading_user("nobody")), 65534)]
        if sandbox.isolation_problem() is None:
            runs.append((dict(isolate=True), None))  # the box's own id
        for how, uid in runs:
            r = sandbox.run(["/bin/sh", "-c", script], Limits(seconds=20), writable=[folder], **how)
            self.assertEqual(r.status, "ok", r.stderr)
            got = int(r.stdout)
            if uid is None:
                self.assertGreaterEqual(got, users.BOX_UID_BASE)  # owns nothing of the machine
            else:
                self.assertEqual(got, uid)
            # What it made there is the caller's again afterwards.
            self.assertEqual(os.stat(os.path.join(folder, "made.txt")).st_uid, os.getuid())
            self.assertEqual(os.stat(folder).st_uid, os.getuid())

    def test_a_pipe_passed_through_is_the_commands(self):
        runs = [dict(isolate=False)] + ([dict(isolate=True)] if sandbox.isolation_problem() is None else [])
        for how in runs:
            r, w = os.pipe()
            res = sandbox.run(["/bin/sh", "-c", f"echo through >&{w}"], Limits(seconds=20), pass_fds=(w,),
                              writable=[tempfile.mkdtemp()], **how)
            self.assertEqual((res.status, os.read(r, 100)), ("ok", b"through\n"))
            with self.assertRaises(OSError):  # run closed its copy once the command started
                os.close(w)
            os.close(r)

    def test_the_time_and_output_limits(self):
        started = time.monotonic()
        r = sandbox.run(["sleep", "20"], Limits(seconds=0.5), isolate=False)
        self.assertEqual(r.status, "time limit")
        self.assertLess(time.monotonic() - started, 10)
        r = sandbox.run(["yes"], Limits(seconds=20, output_mb=0.5), isolate=False, keep=100)
        self.assertEqual((r.status, len(r.stdout)), ("output limit", 100))

    def test_stop_all_ends_the_runs_and_refuses_new_ones(self):
        raised = []

        def one():
            try:
                sandbox.run(["sleep", "30"], Limits(seconds=60), isolate=False)
            except sandbox.Stopped:
                raised.append(True)

        thread = threading.Thread(target=one)
        started = time.monotonic()
        thread.start()
        time.sleep(0.5)
        try:
            sandbox.stop_all()
            thread.join(20)
            self.assertEqual(raised, [True])
            self.assertLess(time.monotonic() - started, 10)
            with self.assertRaises(sandbox.Stopped):
                sandbox.run(["true"], Limits(), isolate=False)
        finally:
            sandbox._stop.clear()  # this process runs other tests after this one


if __name__ == "__main__":
    unittest.main()
