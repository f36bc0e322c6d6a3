"""Why grading one tree stops: GradeError (it cannot start or go on), OutOfTime (its
overall deadline passed) and NotGraded (the grading machine failed). Raised by the grading
modules, caught by grade.py's callers."""


class GradeError(Exception):
    """Grading cannot start or go on: a bad option, a tree that is not a workbook, the
    grading tree does not configure, no isolation. The message is one line; `code` is the
    exit status of ./workbook grade."""

    def __init__(self, message, code=1):
        super().__init__(message)
        self.code = code


class OutOfTime(Exception):
    """The whole grading of one tree passed its deadline (the class grader's
    --student-timeout)."""


NOT_GRADED_EXIT = 75  # ./workbook grade's exit status for NotGraded (sysexits' EX_TEMPFAIL)


class NotGraded(Exception):
    """The grading machine failed, not the student's code: its disk is full, staging the
    submission failed. No points and nothing cached: the message says why, and grading the
    same submission again once that is fixed gives its grade."""
