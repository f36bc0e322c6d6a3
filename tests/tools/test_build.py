"""Unit tests of the build helper (tools/build.py): the commands it gives, whether a folder
is configured with the settings wanted, the first error in a line, and a real configure and
build of a two-file project (a few seconds)."""
import io
import os
import shutil
import tempfile
import unittest

from tests.tools import scratch  # noqa: F401  (tempfile's folders go into one removed at exit)

from tools import build


class Commands(unittest.TestCase):
    def test_a_preset_tree_in_the_presets_folder_with_settings_on_top(self):
        tree = build.Tree.of_preset("/r", "release", BOXES_LTO="OFF")
        self.assertEqual(tree.build, "/r/build/release")
        self.assertEqual(build.configure_command(tree),
                         ["cmake", "-S", "/r", "-B", "/r/build/release", "--preset", "release",
                          "-DBOXES_LTO=OFF"])

    def test_a_tree_without_presets_as_the_grader_configures_it(self):
        tree = build.Tree("/w/src", "/w/build", cache={"BOXES_GRADING": "ON", "BOXES_WINDOW": "OFF"})
        self.assertEqual(build.configure_command(tree),
                         ["cmake", "-S", "/w/src", "-B", "/w/build", "-G", "Ninja",
                          "-DBOXES_GRADING=ON", "-DBOXES_WINDOW=OFF"])
        self.assertEqual(build.regenerate_command(tree),
                         ["cmake", "--build", "/w/build", "--target", "build.ninja"])
        self.assertEqual(build.build_command(tree, ["test_step01", "x.o"], jobs=2),
                         ["cmake", "--build", "/w/build", "--target", "test_step01", "x.o", "--", "-j2"])

    def test_a_configured_ninja_tree_is_built_by_ninja_itself(self):
        with tempfile.TemporaryDirectory() as tmp:
            ninja = os.path.join(tmp, "ninja")
            with open(ninja, "w") as f:
                f.write("#!/bin/sh\n")
            os.chmod(ninja, 0o755)
            with open(os.path.join(tmp, "CMakeCache.txt"), "w") as f:
                f.write(f"CMAKE_MAKE_PROGRAM:FILEPATH={ninja}\n")
            tree = build.Tree("/w", tmp)
            # No build.ninja yet: cmake --build, as before.
            self.assertEqual(build.build_command(tree, ["a"])[:2], ["cmake", "--build"])
            open(os.path.join(tmp, "build.ninja"), "w").close()
            self.assertEqual(build.build_command(tree, ["test_step01"], jobs=2),
                             [ninja, "-C", tmp, "test_step01", "-j2"])

    def test_configured_means_build_files_and_the_settings_wanted(self):
        with tempfile.TemporaryDirectory() as tmp:
            tree = build.Tree(tmp, tmp, cache={"BOXES_GRADING": "ON"})
            self.assertFalse(build.configured(tree))
            with open(os.path.join(tmp, "build.ninja"), "w") as f:
                f.write("")
            with open(os.path.join(tmp, "CMakeCache.txt"), "w") as f:
                f.write("// a comment\nBOXES_GRADING:BOOL=OFF\n")
            self.assertFalse(build.configured(tree))
            with open(os.path.join(tmp, "CMakeCache.txt"), "w") as f:
                f.write("BOXES_GRADING:BOOL=ON\nCMAKE_BUILD_TYPE:STRING=Release\n")
            self.assertTrue(build.configured(tree))


    def test_a_folder_configured_before_its_preset_gained_a_setting_is_configured_again(self):
        with tempfile.TemporaryDirectory() as tmp:
            with open(os.path.join(tmp, "CMakePresets.json"), "w") as f:
                f.write('{"version": 3, "configurePresets": ['
                        '{"name": "base", "cacheVariables": {"CMAKE_BUILD_TYPE": "Release"}},'
                        '{"name": "student", "inherits": "base", "cacheVariables": {'
                        '"BOXES_PCH": "ON", "CMAKE_CXX_COMPILER": "g++",'
                        '"FLAGS": {"type": "STRING", "value": "-O1 -DNDEBUG"}}}]}')
            tree = build.Tree.of_preset(tmp, "student", BOXES_TESTS="ON")
            self.assertEqual(build.preset_settings(tmp, "student"),
                             {"CMAKE_BUILD_TYPE": "Release", "BOXES_PCH": "ON", "FLAGS": "-O1 -DNDEBUG"})
            os.makedirs(tree.build)
            open(os.path.join(tree.build, "build.ninja"), "w").close()
            old = ("CMAKE_BUILD_TYPE:STRING=Release\nFLAGS:STRING=-O1 -DNDEBUG\n"
                   "CMAKE_CXX_COMPILER:FILEPATH=/usr/bin/g++\nBOXES_TESTS:BOOL=ON\n")
            with open(os.path.join(tree.build, "CMakeCache.txt"), "w") as f:
                f.write(old)  # configured before the preset had BOXES_PCH
            self.assertFalse(build.configured(tree))
            with open(os.path.join(tree.build, "CMakeCache.txt"), "w") as f:
                f.write(old + "BOXES_PCH:BOOL=ON\n")
            self.assertTrue(build.configured(tree))
            tree.cache["BOXES_PCH"] = "OFF"  # the tree's own settings win over the preset's
            self.assertFalse(build.configured(tree))


class FirstError(unittest.TestCase):
    SRC = "/w/src"

    def test_the_compilers_error_relative_to_the_tree(self):
        log = ("[1/3] Building CXX object x.o\nFAILED: x.o\n"
               "/w/src/steps/01_x/x.cpp:40:1: error: expected ';' before '}' token\n")
        self.assertEqual(build.first_error(log, self.SRC),
                         "steps/01_x/x.cpp:40:1: error: expected ';' before '}' token")
        self.assertEqual(build.first_error(log, self.SRC, brief=True),
                         "steps/01_x/x.cpp:40: expected ';' before '}' token")

    def test_a_build_folder_inside_the_tree_gives_paths_relative_to_it(self):
        log = "FAILED: x.o\n../../steps/01_triangle/triangle.cpp:60:5: error: 'foo' was not declared\n"
        self.assertEqual(build.first_error(log, "/r", brief=True),
                         "steps/01_triangle/triangle.cpp:60: 'foo' was not declared")

    def test_the_linker_ninja_and_nothing(self):
        self.assertEqual(build.first_error("x.o: undefined reference to `f()'\n", self.SRC),
                         "x.o: undefined reference to `f()'")
        self.assertEqual(build.first_error("FAILED: tests/test_step01\n", self.SRC),
                         "FAILED: tests/test_step01")
        self.assertEqual(build.first_error("nothing useful\n", self.SRC), "the build failed")


PROJECT = """cmake_minimum_required(VERSION 3.22)
project(p LANGUAGES CXX)
option(WITH_B "b" ON)
add_executable(a a.cpp)
if(WITH_B)
    add_executable(b b.cpp)
endif()
"""


@unittest.skipUnless(shutil.which("cmake") and shutil.which("ninja") and shutil.which("c++"),
                     "needs cmake, ninja and a C++ compiler")
class RealBuild(unittest.TestCase):
    def test_configure_build_only_the_targets_asked_and_say_the_error(self):
        with tempfile.TemporaryDirectory() as src:
            with open(os.path.join(src, "CMakeLists.txt"), "w") as f:
                f.write(PROJECT)
            with open(os.path.join(src, "a.cpp"), "w") as f:
                f.write("int main() { return 0; }\n")
            with open(os.path.join(src, "b.cpp"), "w") as f:
                f.write("int main() { return missing; }\n")
            tree = build.Tree(src, os.path.join(src, "out"), cache={"WITH_B": "ON"})
            said = []
            r = build.configure(tree, say=said.append)
            self.assertTrue(r.ok, r.output)
            self.assertEqual(len(said), 1)
            self.assertTrue(build.configured(tree))
            self.assertEqual(build.configure(tree, say=said.append).output, "")  # once
            stream = io.StringIO()
            r = build.build(tree, ["a"], progress=build.Progress("[t]", stream, every=0))
            self.assertTrue(r.ok, r.output)
            self.assertEqual(r.steps, 2)  # a.cpp's object and the link
            self.assertIn("[t]   2/2 built", stream.getvalue())
            self.assertTrue(os.path.exists(os.path.join(tree.build, "a")))
            self.assertFalse(os.path.exists(os.path.join(tree.build, "b")))
            r = build.build(tree, ["b"])
            self.assertFalse(r.ok)
            self.assertRegex(r.error, r"^b\.cpp:1: .missing. was not declared in this scope$")


if __name__ == "__main__":
    unittest.main()
