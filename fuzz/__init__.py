"""The fuzzers: C++ targets (libFuzzer), and fuzz_results in Python, run as a module from the
repository root: python3 -m fuzz.fuzz_results (fuzz.sh, ctest's replay)."""
