"""The Python tests run as modules from the repository root, beside the tools package they
test: python3 -m tests.tools.test_grade, python3 -m tests.grading_test SCENARIO WORK_DIR."""
