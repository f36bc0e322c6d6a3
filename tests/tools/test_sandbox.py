"""Unit tests of tools/grading/sandbox.py: how a run's end becomes its reason, the
bubblewrap command line, the limits, and stopping every run."""
import os
import signal
import sys
import tempfile
import threading
import time
import unittest
from unittest import mock
import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from tools.grading import sandbox  # noqa: E402
from tools.grading.sandbox import Limits, _classify  # noqa: E402


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


class BubblewrapPrefix(unittest.TestCase):
    def test_hidden_folders_are_covered_and_readable_ones_shown(self):
        home = os.path.expanduser("~")
        work = os.path.join(home, "boxes-test-no-such-folder")
        # A path made absent here: "/nonexistent" is a system user's home, which a tool
        # running as such a user may create.
        with tempfile.TemporaryDirectory() as scratch:
            absent = os.path.join(scratch, "absent")
        prefix = sandbox.bwrap_prefix([work], work, 1 << 20, hidden=["/tmp", home, absent],
                                      readable=["/usr"])
        text = " ".join(prefix)
        self.assertIn(f"--tmpfs {home}", text)
        self.assertIn(f"--remount-ro {home}", text)
        self.assertNotIn(f"--tmpfs {absent}", text)  # only folders that exist
        self.assertIn(f"--size {1 << 20} --tmpfs /tmp", text)
        self.assertIn("--ro-bind /usr /usr", text)
        self.assertIn(f"--bind {work} {work}", text)
        self.assertEqual(prefix[prefix.index("--chdir") + 1], work)
        for flag in ("--unshare-all", "--cap-drop", "--die-with-parent", "--disable-userns"):
            self.assertIn(flag, prefix)
        # The cover goes on before the writable bind inside it, the remount after.
        self.assertLess(prefix.index("--tmpfs"), prefix.index("--bind"))
        self.assertLess(prefix.index("--bind"), prefix.index("--remount-ro"))


class OlderBubblewrap(unittest.TestCase):
    def test_options_it_lacks_are_left_out(self):
        with mock.patch.object(sandbox, "bwrap_has", lambda option: False):  # Ubuntu 22.04's 0.6
            prefix = sandbox.bwrap_prefix(["/w"], "/w", 1 << 20)
        self.assertNotIn("--disable-userns", prefix)
        self.assertNotIn("--size", prefix)
        self.assertIn("--unshare-user", prefix)
        self.assertEqual(prefix[prefix.index("--tmpfs") + 1], "/tmp")


class CpuQuota(unittest.TestCase):
    def layout(self, cgroup_lines, mounts, files):
        root = tempfile.mkdtemp()
        for rel, text in files.items():
            os.makedirs(os.path.dirname(os.path.join(root, rel)), exist_ok=True)
            with open(os.path.join(root, rel), "w") as f:
                f.write(text)
        with open(os.path.join(root, "cgroup"), "w") as f:
            f.write(cgroup_lines)
        with open(os.path.join(root, "mounts"), "w") as f:
            f.write(mounts.replace("ROOT", root))
        return os.path.join(root, "cgroup"), os.path.join(root, "mounts")

    def test_cgroup_v2_in_a_container_and_on_a_host(self):
        # A container's namespace shows its cgroup as /: the quota is at the mount's root.
        args = self.layout("0::/\n", "cgroup2 ROOT/fs cgroup2 rw 0 0\n", {"fs/cpu.max": "50000 100000\n"})
        self.assertEqual(sandbox.cgroup_cpu_quota(*args), 0.5)
        # On a host: the tightest of the cgroup and its parents.
        args = self.layout("0::/a/b\n", "cgroup2 ROOT/fs cgroup2 rw 0 0\n",
                           {"fs/cpu.max": "max 100000\n", "fs/a/cpu.max": "150000 100000\n",
                            "fs/a/b/cpu.max": "max 100000\n"})
        self.assertEqual(sandbox.cgroup_cpu_quota(*args), 1.5)

    def test_cgroup_v1_and_none(self):
        args = self.layout("4:cpu,cpuacct:/docker/abc\n", "cgroup ROOT/cpu cgroup rw,cpu,cpuacct 0 0\n",
                           {"cpu/cpu.cfs_quota_us": "200000\n", "cpu/cpu.cfs_period_us": "100000\n"})
        self.assertEqual(sandbox.cgroup_cpu_quota(*args), 2.0)  # the path is not there: the mount's root
        args = self.layout("4:cpu,cpuacct:/\n", "cgroup ROOT/cpu cgroup rw,cpu,cpuacct 0 0\n",
                           {"cpu/cpu.cfs_quota_us": "-1\n", "cpu/cpu.cfs_period_us": "100000\n"})
        self.assertIsNone(sandbox.cgroup_cpu_quota(*args))

    def test_usable_cpus(self):
        self.assertTrue(1 <= sandbox.usable_cpus() <= (os.cpu_count() or 1))


class LimitsAndRuns(unittest.TestCase):
    def test_cpu_seconds_cover_every_core(self):
        self.assertEqual(Limits(seconds=10).cpu_seconds(), 10 * sandbox.usable_cpus() + 1)

    def test_a_run_without_isolation(self):
        r = sandbox.run(["sh", "-c", "echo hi; echo oops >&2; exit 4"], Limits(seconds=10), isolate=False)
        self.assertEqual((r.status, r.reason, r.stdout, r.stderr), ("failed", "failed: exit 4", b"hi\n", b"oops\n"))

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
