"""The workbook's tools: grading/ for instructors (the starter kit, grading one tree or a
class, Gradescope, GitHub Classroom, the sandbox), bench/ for measuring step 04 beside
Embree, report.py for the tour's page, deps.sh for the Debian packages every command needs.
The Python tools run as modules from the repository root (./workbook does that):
python3 -m tools.grading.grade, python3 -m tools.report, python3 -m tools.bench.bench04, ...
ROOT, the workbook tree they belong to, is worked out here once; the others import it."""
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
