"""Unit tests of tools/grading/sandbox.py: how a run's end becomes its reason, the
bubblewrap command line, the limits, and stopping every run."""
import os
import signal
import sys
import threading
import time
import unittest

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
        prefix = sandbox.bwrap_prefix([work], work, 1 << 20, hidden=["/tmp", home, "/nonexistent"],
                                      readable=["/usr"])
        text = " ".join(prefix)
        self.assertIn(f"--tmpfs {home}", text)
        self.assertIn(f"--remount-ro {home}", text)
        self.assertNotIn("--tmpfs /nonexistent", text)  # only folders that exist
        self.assertIn(f"--size {1 << 20} --tmpfs /tmp", text)
        self.assertIn("--ro-bind /usr /usr", text)
        self.assertIn(f"--bind {work} {work}", text)
        self.assertEqual(prefix[prefix.index("--chdir") + 1], work)
        for flag in ("--unshare-all", "--cap-drop", "--die-with-parent", "--disable-userns"):
            self.assertIn(flag, prefix)
        # The cover goes on before the writable bind inside it, the remount after.
        self.assertLess(prefix.index("--tmpfs"), prefix.index("--bind"))
        self.assertLess(prefix.index("--bind"), prefix.index("--remount-ro"))


class LimitsAndRuns(unittest.TestCase):
    def test_cpu_seconds_cover_every_core(self):
        self.assertEqual(Limits(seconds=10).cpu_seconds(), 10 * (os.cpu_count() or 1) + 1)

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
