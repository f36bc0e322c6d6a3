"""The differential tests' data: ./workbook differential.

Each exercise's tests compare the student's answers with the reference's on generated inputs
(tests/differential/harness.hpp). The reference's answers for the shipped inputs (seed 1)
are files in tests/differential/data/, which the starter kit keeps, so its tests are as
strong as the tree's. They are written from this tree, the reference, by the program
differential_data (tests/differential/generate.cpp):

usage: ./workbook differential --write [NAME | N.M ...]   the shipped sets, again (after a change)
       ./workbook differential --check                    the shipped sets are this tree's answers
       ./workbook differential --hidden DIR --seed S      hidden sets for ./workbook grade --hidden DIR
       ./workbook differential --show NAME [--seed S]     each input in words, its family and answer
       ./workbook differential --list                     the data sets

A hidden set is the same data for another seed, written as doctest files
DIR/stepNN_differential_hidden.cpp (the inputs are regenerated from the seed in them); give
DIR to ./workbook grade --hidden. Keep them from the students: they hold the answers.
"""
import os
import subprocess
import sys

from . import ROOT

BUILD = os.path.join(ROOT, "build", "release")
DATA = os.path.join("tests", "differential", "data")


def build():
    """Builds differential_data in the release build; its path, or None."""
    if not os.path.isfile(os.path.join(BUILD, "build.ninja")):
        r = subprocess.run(["cmake", "--preset", "release"], cwd=ROOT)
        if r.returncode != 0:
            return None
    r = subprocess.run(["nice", "cmake", "--build", BUILD, "--target", "differential_data"], cwd=ROOT)
    if r.returncode != 0:
        return None
    return os.path.join(BUILD, "tests", "differential", "differential_data")


def main(argv):
    if not argv or argv[0] in ("-h", "--help"):
        print(__doc__.split("usage:", 1)[1].split("\n\n")[0].rstrip())
        return 0 if argv else 2
    if not os.path.isfile(os.path.join(ROOT, "tools", "grading", "grade.py")):
        print("differential: the data is written from the reference tree (with the solutions), "
              "not from a starter kit", file=sys.stderr)
        return 2
    mode, rest = argv[0], argv[1:]
    if mode not in ("--write", "--check", "--hidden", "--show", "--list"):
        print(f"differential: unknown option '{mode}' (--write, --check, --hidden, --show, --list)",
              file=sys.stderr)
        return 2
    program = build()
    if not program:
        print("differential: building differential_data failed", file=sys.stderr)
        return 1
    if mode in ("--write", "--check"):
        cmd = [program, mode, os.path.join(ROOT, DATA)] + rest
    elif mode == "--hidden":
        if not rest:
            print("differential: --hidden DIR --seed S", file=sys.stderr)
            return 2
        os.makedirs(rest[0], exist_ok=True)
        cmd = [program, mode] + rest
    else:
        cmd = [program, mode] + rest
    return subprocess.run(cmd).returncode


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
