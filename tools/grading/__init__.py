"""The instructor's side: the starter kit and grading (see docs/instructors.md).

exercises    the exercise markers in the sources and doctest's XML results
kit          the starter kit: the tree with every solution block replaced by a stub
classroom    the kit's GitHub Classroom workflow
sandbox      runs one untrusted command isolated (bubblewrap) and limited (sandbox.sh)
submissions  a student's submission (folder, git repository, archive) read safely
grade        grades one tree: ./workbook grade; its parts: grading_tree (the tree it
             grades), build_and_run (a step's build and cases), box (how student code
             runs), grade_report (the table and its files), errors
grade_class  grades a folder of submissions in parallel: ./workbook grade-class
gradescope   the Gradescope autograder bundle: ./workbook gradescope
class_bench  a generated class, its expected points, and the class grader's benchmark

The grader (grade and its parts, grade_class, gradescope, class_bench) needs the solutions
and stays out of the starter kit; the kit keeps the rest (the tour's report reads exercises)."""
from .. import ROOT  # noqa: F401  (the workbook tree: tools.ROOT, here for the grading modules)
