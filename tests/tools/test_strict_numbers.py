"""Unit tests of tools/grading/strict_numbers.py and of the sandbox's numbers: an overflowing,
a fractional and a trailing-junk value is refused with one line naming the flag and the
value, never read as another number. The grader's own command lines (grade, grade-class,
gradescope, class_bench: not in the starter kit) are tested the same way in test_grade.py."""
import argparse
import contextlib
import io
import unittest

from tools.grading import sandbox
from tools.grading.strict_numbers import decimal, integer, integer_list, step_list


def refusal(main, argv):
    """(exit code, stderr) of main(argv), which must stop in argparse."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(argv)
        except SystemExit as e:
            code = e.code
    return code, err.getvalue()


class Types(unittest.TestCase):
    def refused(self, read, text):
        with self.assertRaises(argparse.ArgumentTypeError) as e:
            read(text)
        return str(e.exception)

    def test_integer_takes_decimal_digits_within_bounds_only(self):
        read = integer(1, 1024)
        self.assertEqual((read("1"), read("1024"), read("007")), (1, 1024, 7))
        self.assertEqual(self.refused(read, "1025"), "1025 is out of range (1 to 1024)")
        self.assertEqual(self.refused(read, "0"), "0 is out of range (1 to 1024)")
        self.assertEqual(self.refused(read, "99999999999999999999999"),
                         "99999999999999999999999 is out of range (1 to 1024)")
        # int() takes each of these; a count must not.
        for text in ("2.5", "4x", "1_000", " 4", "4\n", "+4", "٤", "0x10", "", "-"):
            self.assertEqual(self.refused(read, text), f"'{text}' is not a decimal integer")

    def test_decimal_takes_finite_decimal_numbers_within_bounds_only(self):
        read = decimal(0, 100)
        self.assertEqual((read("2.5"), read("1e2"), read(".5"), read("3.")), (2.5, 100.0, 0.5, 3.0))
        self.assertEqual(self.refused(read, "0"), "0 is out of range (above 0, at most 100)")
        self.assertEqual(self.refused(read, "1e999"), "1e999 is out of range (above 0, at most 100)")
        # float() takes each of these: nan and inf would make every limit fail or none.
        for text in ("nan", "inf", "Infinity", "1_0", "5s", " 5", "0x10", "1e", ""):
            self.assertEqual(self.refused(read, text), f"'{text}' is not a decimal number")

    def test_lists(self):
        self.assertEqual(integer_list(1, 8)("1,2,8"), [1, 2, 8])
        self.assertEqual(self.refused(integer_list(1, 8), "1,2.5"), "'1,2.5': '2.5' is not a decimal integer")
        self.assertEqual(step_list("1,03"), ["01", "03"])
        for text in ("1.5", "01x", "001", "", "1,,2"):
            self.assertIn("is not a step number", self.refused(step_list, text))


class FlagChecks:
    """Each flag with an overflowing, a fractional and a trailing-junk value."""

    BAD_INTEGERS = ("99999999999999999999999", "2.5", "4abc")
    BAD_DECIMALS = ("1e999", "nan", "5abc")

    def check(self, main, prefix, flag, values):
        for value in values:
            with self.subTest(flag=flag, value=value):
                code, err = refusal(main, prefix + [flag, value])
                self.assertEqual(code, 2)
                last = err.strip().splitlines()[-1]
                self.assertIn(f"argument {flag}: ", last)
                self.assertIn(value, last)



class CommandLines(FlagChecks, unittest.TestCase):
    def test_sandbox(self):
        for flag in ("--memory", "--processes"):
            self.check(sandbox.main, [], flag, self.BAD_INTEGERS)
        for flag in ("--time", "--output"):
            self.check(sandbox.main, [], flag, self.BAD_DECIMALS)


if __name__ == "__main__":
    unittest.main()
