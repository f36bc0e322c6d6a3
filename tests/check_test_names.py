#!/usr/bin/python3
"""Fails when a doctest case name would break its ctest test.

doctest_discover_tests makes one ctest test per case and runs it with --test-case=NAME.
A ';' in a name is CMake's list separator: the case becomes two tests that select no case
and pass without running anything, so the case itself never runs under ctest. A ',' is escaped for doctest but drops the case's label, so `ctest -L SUITE`
(the FP-trap run, one exercise's tests) skips it.
usage: check_test_names.py TESTS_DIR"""
import glob
import re
import sys

bad = 0
for path in sorted(glob.glob(sys.argv[1] + "/*.cpp")):
    src = open(path, encoding="utf-8").read()
    # TEST_CASE("a" "b"): clang-format splits long names into adjacent literals.
    for m in re.finditer(r'TEST_CASE\(\s*((?:"(?:[^"\\]|\\.)*"\s*)+)', src):
        name = "".join(re.findall(r'"((?:[^"\\]|\\.)*)"', m.group(1)))
        if ";" in name or "," in name:
            line = src.count("\n", 0, m.start()) + 1
            print("%s:%d: test case name with ';' or ',': %s" % (path, line, name))
            bad += 1
print("%d test case names with ';' or ','" % bad)
sys.exit(1 if bad else 0)
