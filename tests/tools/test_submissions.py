"""Unit tests of tools/grading/submissions.py: what of a submission is read, and what is
refused."""
import io
import os
import sys
import tarfile
import tempfile
import unittest
import zipfile
import scratch  # noqa: F401  (tempfile's folders: one, removed at exit)

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
from tools.grading import submissions  # noqa: E402
from tools.grading.submissions import (SubmissionError, _step_relpath, content_hash, is_submission,  # noqa: E402
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


if __name__ == "__main__":
    unittest.main()
