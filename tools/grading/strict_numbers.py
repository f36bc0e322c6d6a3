"""Numbers on the grader's command lines, read exactly.

argparse's type=int and type=float take more than a number: "1_000", " 5 ", "+5" and other
scripts' digits for int; "nan", "inf", "1e999" (infinity) and "1_0.5" for float. A time
limit of nan or inf, or a memory limit beyond what setrlimit takes, would be silently a
different limit or a crash. These types take a decimal integer or a finite decimal number,
all of the text, within stated bounds, and refuse anything else with one line naming it."""
import argparse
import math
import re

_INTEGER = re.compile(r"-?[0-9]+")  # [0-9]: ASCII digits only (\d takes any script's)
_DECIMAL = re.compile(r"-?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][-+]?[0-9]+)?")


def integer(low, high):
    """An argparse type: a decimal integer from low to high."""
    def read(text):
        if not _INTEGER.fullmatch(text):
            raise argparse.ArgumentTypeError(f"'{text}' is not a decimal integer")
        value = int(text)
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{text} is out of range ({low} to {high})")
        return value
    read.__name__ = "integer"
    return read


def decimal(low, high):
    """An argparse type: a finite decimal number above low (exclusive) and at most high."""
    def read(text):
        if not _DECIMAL.fullmatch(text):
            raise argparse.ArgumentTypeError(f"'{text}' is not a decimal number")
        value = float(text)
        if not (math.isfinite(value) and low < value <= high):
            raise argparse.ArgumentTypeError(f"{text} is out of range (above {low:g}, at most {high:g})")
        return value
    read.__name__ = "decimal"
    return read


def integer_list(low, high):
    """An argparse type: comma-separated decimal integers from low to high ("1,2,4")."""
    one = integer(low, high)

    def read(text):
        try:
            return [one(part) for part in text.split(",")]
        except argparse.ArgumentTypeError as e:
            raise argparse.ArgumentTypeError(f"'{text}': {e}") from None
    read.__name__ = "integer list"
    return read


def step_list(text):
    """An argparse type: step numbers "01,03" (or "1,3"), each two digits at most, made
    two-digit; which steps exist is checked where they are known."""
    steps = []
    for part in text.split(","):
        if not re.fullmatch(r"[0-9]{1,2}", part):
            raise argparse.ArgumentTypeError(f"step '{part}' is not a step number such as 01")
        steps.append(part.zfill(2))
    return steps


step_list.__name__ = "step list"

# Bounds shared by the grader's commands.
MAX_SECONDS = 7 * 24 * 3600.0  # a week: any longer limit is a typing error
MAX_MB = 1 << 20  # 1 TiB; setrlimit takes bytes in 64 bits
MAX_JOBS = 1024
