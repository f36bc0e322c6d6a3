"""The tools' unit tests: python3 -m tests.tools.test_MODULE, from the repository root."""
