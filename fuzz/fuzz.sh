#!/usr/bin/env bash
# Fuzzes every target (or the ones named) for SECONDS each, one after the other, with
# clang's libFuzzer under ASan+UBSan, at the lowest CPU priority.
# usage: fuzz/fuzz.sh SECONDS [TARGET...]
#        (targets: obj flags vec3 scene rays sbvh exam_answer results; results is Python)
# Seeds come from fuzz/corpus/TARGET/ (committed). New coverage goes to build/fuzz/work/
# TARGET/ (not committed); every crashing, leaking or hanging input found is copied into
# fuzz/corpus/TARGET/ so the replay test (ctest -L fuzz-replay) keeps it: commit it with
# the fix. The target results (the grader's reading of test results: Python) runs
# fuzz/fuzz_results.py with Hypothesis instead. Exit status 1 when any target found something.
set -euo pipefail
cd "$(dirname "$0")/.."
[[ $# -ge 1 && $1 =~ ^[0-9]+$ ]] || { sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 2; }
seconds=$1
shift
targets=("$@")
[[ ${#targets[@]} -gt 0 ]] || targets=(obj flags vec3 scene rays sbvh exam_answer results)

tools/deps.sh build fuzz
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -- -j2

found=0
for t in "${targets[@]}"; do
  bin=build/fuzz/fuzz/fuzz_$t
  [[ $t == results || -x $bin ]] || { echo "fuzz.sh: no target '$t'" >&2; exit 2; }
  work=build/fuzz/work/$t
  artifacts=build/fuzz/artifacts/$t
  rm -rf "$artifacts"  # what earlier runs found is in the corpus already
  mkdir -p "$work" "$artifacts"
  echo "== fuzz_$t for $seconds s (log: build/fuzz/$t.log)"
  status=0
  if [[ $t == results ]]; then
    # Hypothesis in Debian's Python (the grader's interpreter); an input that crashes the
    # interpreter itself is left in $artifacts/current and kept as crash-SHA1.
    (ulimit -v 4194304 && exec nice -n 19 /usr/bin/python3 -m fuzz.fuzz_results "$seconds" \
      --artifacts "$artifacts") >"build/fuzz/$t.log" 2>&1 || status=$?
    if [[ -f $artifacts/current ]]; then
      mv "$artifacts/current" "$artifacts/crash-$(sha1sum "$artifacts/current" | cut -c1-40)"
    fi
  else
    # -timeout: an input taking longer than 30 s is a hang (under load, on a shared machine,
    # ASan's allocator can stall for over 10 s in madvise: false timeouts);
    # -rss_limit_mb: a memory blow-up is a finding, not an out-of-memory kill of the machine.
    ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      nice -n 19 "$bin" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=2048 \
      -max_len=4096 -print_final_stats=1 -artifact_prefix="$artifacts/" \
      "$work" "fuzz/corpus/$t" >"build/fuzz/$t.log" 2>&1 || status=$?
  fi
  grep -E '^stat::number_of_executed_runs|^#[0-9]+.*DONE' "build/fuzz/$t.log" | tail -2 || true
  shopt -s nullglob
  for a in "$artifacts"/crash-* "$artifacts"/leak-* "$artifacts"/timeout-* "$artifacts"/oom-*; do
    cp -n "$a" "fuzz/corpus/$t/"
    echo "   found: $a (copied into fuzz/corpus/$t/)"
    found=1
  done
  shopt -u nullglob
  if [[ $status -ne 0 ]]; then
    echo "   fuzz_$t stopped with status $status: see build/fuzz/$t.log"
    found=1
  fi
done
exit $found
