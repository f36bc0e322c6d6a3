"""Unit tests of tools/grading/submissions.py: what of a submission is read, and what is
refused."""
import io
import os
import stat
import struct
import tarfile
import tempfile
import unittest
import zipfile
from unittest import mock
from tests.tools import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

from tools.grading import submissions
from tools.grading.submissions import (SubmissionError, _step_relpath, content_hash, is_submission,
                                       read_submission, stage, student_name)


class Paths(unittest.TestCase):
    def test_step_sources_under_any_top_folder(self):
        self.assertEqual(_step_relpath("alice/steps/01_triangle/triangle.cpp"),
                         ("alice/", "steps/01_triangle/triangle.cpp"))
        self.assertEqual(_step_relpath("steps/04_bvh/advanced/wide.hpp"), ("", "steps/04_bvh/advanced/wide.hpp"))
        self.assertEqual(_step_relpath("a\\steps\\01_x\\x.cc"), ("a/", "steps/01_x/x.cc"))

    def test_unsafe_or_foreign_paths_are_skipped(self):
        for name in ("/steps/01_x/x.cpp", "a/../steps/01_x/x.cpp", "steps/01_x/../../x.cpp",
                     "__MACOSX/steps/01_x/x.cpp", "a/build/steps/01_x/x.cpp", "steps/01_x/README.md",
                     "tests/step01.cpp", "steps/x/x.cpp", "core/steps/1_x/x.cpp"):
            self.assertIsNone(_step_relpath(name), name)

    def test_student_names(self):
        self.assertEqual(student_name("alice.tar.gz"), "alice")
        self.assertEqual(student_name("Bob.ZIP"), "Bob")
        self.assertEqual(student_name("carol"), "carol")
        self.assertTrue(is_submission("x.tgz"))
        self.assertFalse(is_submission("notes.txt"))


def zip_of(entries, symlink=None):
    path = os.path.join(tempfile.mkdtemp(), "s.zip")
    with zipfile.ZipFile(path, "w") as z:
        for name, data in entries.items():
            z.writestr(name, data)
        if symlink:
            info = zipfile.ZipInfo(symlink)
            info.external_attr = 0o120777 << 16  # a symbolic link
            z.writestr(info, "/etc/passwd")
    return path


class Archives(unittest.TestCase):
    def test_a_zip_gives_the_step_sources_of_its_tree(self):
        path = zip_of({"alice/steps/01_x/x.cpp": "int x;", "alice/README.md": "hi",
                       "alice/other/steps/01_x/y.cpp": "deeper", "../steps/01_x/evil.cpp": "up"},
                      symlink="alice/steps/01_x/link.cpp")
        self.assertEqual(read_submission(path), {"steps/01_x/x.cpp": b"int x;"})

    def test_a_tar_skips_links_and_devices(self):
        path = os.path.join(tempfile.mkdtemp(), "s.tar.gz")
        with tarfile.open(path, "w:gz") as t:
            data = b"int y;"
            info = tarfile.TarInfo("steps/02_y/y.cpp")
            info.size = len(data)
            t.addfile(info, io.BytesIO(data))
            link = tarfile.TarInfo("steps/02_y/link.cpp")
            link.type, link.linkname = tarfile.SYMTYPE, "/etc/shadow"
            t.addfile(link)
            dev = tarfile.TarInfo("steps/02_y/dev.cpp")
            dev.type = tarfile.CHRTYPE
            t.addfile(dev)
        self.assertEqual(read_submission(path), {"steps/02_y/y.cpp": b"int y;"})

    def test_what_is_refused(self):
        with self.assertRaisesRegex(SubmissionError, "no step sources"):
            read_submission(zip_of({"README.md": "nothing"}))
        bad = os.path.join(tempfile.mkdtemp(), "broken.zip")
        with open(bad, "wb") as f:
            f.write(b"not a zip")
        with self.assertRaisesRegex(SubmissionError, "not a readable zip archive"):
            read_submission(bad)
        big = b"x" * (submissions.MAX_FILE_BYTES + 1)
        with self.assertRaisesRegex(SubmissionError, "larger than 4 MB"):
            read_submission(zip_of({"steps/01_x/big.cpp": big}))
        many = {f"steps/01_x/f{i}.hpp": "" for i in range(submissions.MAX_FILES + 1)}
        with self.assertRaisesRegex(SubmissionError, f"more than {submissions.MAX_FILES} step sources"):
            read_submission(zip_of(many))

    def test_a_folder_skips_links(self):
        root = tempfile.mkdtemp()
        os.makedirs(os.path.join(root, "steps", "01_x"))
        with open(os.path.join(root, "steps", "01_x", "x.cpp"), "w") as f:
            f.write("int x;")
        os.symlink("/etc/passwd", os.path.join(root, "steps", "01_x", "link.cpp"))
        self.assertEqual(read_submission(root), {"steps/01_x/x.cpp": b"int x;"})


class Counting(io.BytesIO):
    """A file in memory that counts the bytes read from it."""
    read_bytes = 0

    def read(self, size=-1):
        data = super().read(size)
        self.read_bytes += len(data)
        return data

    def readinto(self, b):
        n = super().readinto(b)
        self.read_bytes += n
        return n


def limited(**limits):
    """The submission reader's limits made small for one test."""
    saved = {k: getattr(submissions, k) for k in limits}

    class Context:
        def __enter__(self):
            for k, v in limits.items():
                setattr(submissions, k, v)

        def __exit__(self, *exc):
            for k, v in saved.items():
                setattr(submissions, k, v)
    return Context()


class Bombs(unittest.TestCase):
    def test_a_tar_with_too_many_members_is_refused_before_it_is_read(self):
        data = io.BytesIO()
        with tarfile.open(fileobj=data, mode="w") as t:
            info = tarfile.TarInfo()
            for i in range(5000):
                info.name = f"junk/{i:05d}"
                t.addfile(info)
        source = Counting(data.getvalue())
        with limited(MAX_MEMBERS=50), self.assertRaisesRegex(SubmissionError, "more than 50 files"):
            submissions._from_tar(source)
        # Refused at the 51st header: what was read is a few buffers, not the 5000 members.
        self.assertLess(source.read_bytes, len(data.getvalue()) // 10)

    def test_declared_sizes_are_counted_before_the_data_is_skipped(self):
        data = io.BytesIO()
        with tarfile.open(fileobj=data, mode="w:gz") as t:
            big = tarfile.TarInfo("junk/zeros")
            big.size = 1 << 20
            t.addfile(big, io.BytesIO(bytes(1 << 20)))
            t.addfile(tarfile.TarInfo("steps/01_x/x.cpp"), io.BytesIO(b""))
        with limited(MAX_ARCHIVE_BYTES=1000), self.assertRaisesRegex(SubmissionError, "hold more than"):
            submissions._from_tar(io.BytesIO(data.getvalue()))

    def test_a_zip_declaring_too_many_members_is_refused_before_zipfile_reads_it(self):
        path = zip_of({f"junk/{i}": "" for i in range(11)} | {"steps/01_x/x.cpp": "int x;"})
        self.assertEqual(submissions.zip_member_count(path), 12)
        with limited(MAX_MEMBERS=10), mock.patch.object(zipfile, "ZipFile", side_effect=AssertionError("read")), \
                self.assertRaisesRegex(SubmissionError, "more than 10 files"):
            read_submission(path)

    def test_a_zip64_end_record_gives_the_count(self):
        # The zip64 end record (count 70,000) and its locator, before a classic end record
        # whose count is 0xFFFF: what a zip of more than 65,535 members ends with.
        zip64 = b"PK\x06\x06" + struct.pack("<QHHIIQQQQ", 44, 45, 45, 0, 0, 70000, 70000, 0, 0)
        locator = b"PK\x06\x07" + struct.pack("<IQI", 0, 0, 1)
        end = b"PK\x05\x06" + struct.pack("<HHHHIIH", 0, 0, 0xFFFF, 0xFFFF, 0, 0, 0)
        path = os.path.join(tempfile.mkdtemp(), "big.zip")
        with open(path, "wb") as f:
            f.write(zip64 + locator + end)
        self.assertEqual(submissions.zip_member_count(path), 70000)

    def test_an_archive_too_large_on_disk(self):
        path = zip_of({"steps/01_x/x.cpp": "int x;"})
        with limited(MAX_ARCHIVE_BYTES=10), self.assertRaisesRegex(SubmissionError, "larger than"):
            read_submission(path)


class Unstageable(unittest.TestCase):
    def test_a_path_that_is_a_file_and_a_folder(self):
        path = zip_of({"t/steps/01_x/x.cpp": "int x;", "t/steps/01_x/x.cpp/y.cpp": "int y;"})
        with self.assertRaisesRegex(SubmissionError, "steps/01_x/x.cpp is both a file and a folder"):
            read_submission(path)

    def test_a_name_too_long_for_a_file_system(self):
        path = zip_of({"t/steps/01_x/x.cpp": "int x;", f"t/steps/01_x/{'n' * 300}.cpp": "int n;"})
        with self.assertRaisesRegex(SubmissionError, "a name longer than 255 bytes"):
            read_submission(path)
        deep = "/".join(["d" * 200] * 6)
        with self.assertRaisesRegex(SubmissionError, "a path longer than 1024 bytes"):
            read_submission(zip_of({f"steps/01_x/{deep}/x.cpp": ""}))

    def test_dot_folders_and_double_slashes_are_the_same_path(self):
        self.assertEqual(_step_relpath("a/./steps//01_x/./x.cpp"), ("a/", "steps/01_x/x.cpp"))


class TreesAreReadNotFollowed(unittest.TestCase):
    def tree(self):
        root = tempfile.mkdtemp()
        step = os.path.join(root, "steps", "01_x")
        os.makedirs(os.path.join(step, "sub"))
        for rel in ("x.cpp", "sub/y.hpp"):
            with open(os.path.join(step, rel), "w") as f:
                f.write("int x;")
        secret = os.path.join(root, "secret.txt")
        with open(secret, "w") as f:
            f.write("SECRET")
        os.chmod(secret, 0o600)
        return root, step, secret

    def test_links_devices_and_fifos_are_refused_with_a_reason(self):
        root, step, secret = self.tree()
        os.symlink(secret, os.path.join(step, "secret.cpp"))
        os.symlink("/proc/self/cwd/steps/01_triangle/triangle.cpp", os.path.join(step, "solution.cpp"))
        os.symlink("/dev/zero", os.path.join(step, "zero.cpp"))
        os.symlink("/", os.path.join(step, "root"))
        os.mkfifo(os.path.join(step, "fifo.cpp"))
        refused = []
        self.assertEqual(submissions.read_tree(root, refused),
                         {"steps/01_x/x.cpp": b"int x;", "steps/01_x/sub/y.hpp": b"int x;"})
        self.assertEqual(sorted(refused), sorted(
            [f"steps/01_x/{n}: a symbolic link, not read (only regular files are graded)"
             for n in ("secret.cpp", "solution.cpp", "zero.cpp", "root")] +
            ["steps/01_x/fifo.cpp: a FIFO, not read (only regular files are graded)"]))

    @unittest.skipUnless(os.geteuid() == 0, "making a device node needs root")
    def test_a_device_node(self):
        root, step, _ = self.tree()
        os.mknod(os.path.join(step, "zero.cpp"), 0o600 | stat.S_IFCHR, os.makedev(1, 5))
        refused = []
        self.assertNotIn("steps/01_x/zero.cpp", submissions.read_tree(root, refused))
        self.assertEqual(refused, ["steps/01_x/zero.cpp: a device, not read (only regular files are graded)"])

    def test_a_linked_steps_folder_or_step_folder(self):
        root, step, _ = self.tree()
        linked = tempfile.mkdtemp()
        os.symlink(os.path.join(root, "steps"), os.path.join(linked, "steps"))
        refused = []
        self.assertEqual(submissions.read_tree(linked, refused), {})
        self.assertEqual(refused, ["steps: a symbolic link, not read (only regular files are graded)"])
        os.rename(step, os.path.join(root, "elsewhere"))
        os.symlink(os.path.join(root, "elsewhere"), step)
        refused = []
        self.assertEqual(submissions.read_tree(root, refused), {})
        self.assertEqual(refused, ["steps/01_x: a symbolic link, not read (only regular files are graded)"])

    def test_the_same_limits_as_a_submission(self):
        root, step, _ = self.tree()
        with limited(MAX_FILES=1), self.assertRaisesRegex(SubmissionError, "more than 1 step sources"):
            submissions.read_tree(root, [])
        with limited(MAX_MEMBERS=2), self.assertRaisesRegex(SubmissionError, "more than 2 files"):
            submissions.read_tree(root, [])
        with open(os.path.join(step, "big.cpp"), "wb") as f:
            f.write(b"x" * 100)
        with limited(MAX_FILE_BYTES=50), self.assertRaisesRegex(SubmissionError, "larger than"):
            submissions.read_tree(root, [])


class HashAndStage(unittest.TestCase):
    def test_the_hash_follows_paths_and_contents_not_order(self):
        a = {"steps/01_x/a.cpp": b"1", "steps/01_x/b.cpp": b"2"}
        self.assertEqual(content_hash(a), content_hash(dict(reversed(list(a.items())))))
        self.assertNotEqual(content_hash(a), content_hash({**a, "steps/01_x/b.cpp": b"3"}))
        self.assertNotEqual(content_hash(a), content_hash({"steps/01_x/c.cpp": b"1", "steps/01_x/b.cpp": b"2"}))

    def test_stage_writes_inside_its_folder_only(self):
        dest = os.path.join(tempfile.mkdtemp(), "tree")
        stage({"steps/01_x/x.cpp": b"int x;"}, dest)
        with open(os.path.join(dest, "steps", "01_x", "x.cpp"), "rb") as f:
            self.assertEqual(f.read(), b"int x;")
        with self.assertRaisesRegex(SubmissionError, "unsafe path"):
            stage({"../escaped.cpp": b""}, dest)
        self.assertFalse(os.path.exists(os.path.join(os.path.dirname(dest), "escaped.cpp")))

    def test_a_link_in_the_way_is_not_written_through(self):
        dest, outside = tempfile.mkdtemp(), os.path.join(tempfile.mkdtemp(), "outside.cpp")
        with open(outside, "w") as f:
            f.write("untouched")
        os.makedirs(os.path.join(dest, "steps"))
        os.symlink(outside, os.path.join(dest, "steps", "x.cpp"))
        with self.assertRaisesRegex(SubmissionError, "steps/x.cpp is a link"):
            submissions.write_files(dest, {"steps/x.cpp": "int x;"})
        with open(outside) as f:
            self.assertEqual(f.read(), "untouched")


if __name__ == "__main__":
    unittest.main()
