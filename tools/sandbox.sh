#!/usr/bin/env bash
# Runs one untrusted command isolated and limited (for the grader: student builds and tests).
# usage: tools/sandbox.sh [--time SECONDS] [--memory MB] [--output MB] [--dir DIR]
#                         [--no-isolation] -- COMMAND [ARGS...]
# Isolation (bubblewrap): the whole system read-only, DIR (default: a fresh temporary
# folder) the only writable place and the working directory, a private /tmp, no network,
# own PID namespace, killed with this script. Limits (prlimit): CPU seconds (and twice
# that in wall time), address space, size of any file written. The command's stdout and
# stderr go to DIR/stdout.txt and DIR/stderr.txt (bounded by the output limit).
# Prints one line "sandbox: RESULT" on stdout: ok | failed: exit N | time limit |
# memory limit | output limit | crashed: SIGNAME. Exit status: 0 ok, 1 failed, 3 limit or
# crash, 2 usage or refused (no user namespaces and no --no-isolation).
set -uo pipefail
time_limit=10 memory_mb=1024 output_mb=16 dir="" isolate=1
while [[ $# -gt 0 ]]; do
  case $1 in
  --time) time_limit=$2; shift 2 ;;
  --memory) memory_mb=$2; shift 2 ;;
  --output) output_mb=$2; shift 2 ;;
  --dir) dir=$2; shift 2 ;;
  --no-isolation) isolate=0; shift ;;
  --) shift; break ;;
  *) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2 ;;
  esac
done
[[ $# -ge 1 ]] || { echo "sandbox: no command given" >&2; exit 2; }
[[ -n $dir ]] || dir=$(mktemp -d /tmp/boxes-sandbox-XXXXXX)
mkdir -p "$dir" && dir=$(cd "$dir" && pwd)

if [[ $isolate -eq 1 ]]; then
  if ! command -v bwrap >/dev/null; then
    echo "sandbox: bubblewrap is not installed (tools/deps.sh grade); refusing to run untrusted code without isolation (--no-isolation to force)" >&2
    exit 2
  fi
  if ! err=$(bwrap --ro-bind / / --unshare-all --die-with-parent true 2>&1); then
    echo "sandbox: bubblewrap cannot create namespaces here (${err%%$'\n'*}); refusing to run untrusted code without isolation (--no-isolation to force)" >&2
    exit 2
  fi
  wrap=(bwrap --ro-bind / / --dev /dev --proc /proc --tmpfs /tmp --bind "$dir" "$dir"
    --chdir "$dir" --unshare-all --die-with-parent --new-session)
else
  echo "sandbox: WARNING: running without isolation (--no-isolation)" >&2
  wrap=()
  cd "$dir" || exit 2
fi

limits=(prlimit --cpu="$time_limit" --as=$((memory_mb << 20)) --fsize=$((output_mb << 20)) --core=0)
wall=$((2 * time_limit + 1))
timeout --signal=KILL "$wall" "${wrap[@]}" "${limits[@]}" -- "$@" \
  >"$dir/stdout.txt" 2>"$dir/stderr.txt" </dev/null
status=$?

result="ok" code=0
if [[ $status -ne 0 ]]; then
  code=3
  if grep -qE "bad_alloc|MemoryError|Cannot allocate memory|out of memory" "$dir/stderr.txt" 2>/dev/null; then
    result="memory limit"
  elif [[ $status -eq 137 || $status -eq $((128 + 24)) ]]; then
    result="time limit"  # SIGKILL from the wall-clock timeout, or SIGXCPU
  elif [[ $status -eq $((128 + 25)) ]]; then
    result="output limit"  # SIGXFSZ
  elif [[ $status -gt 128 ]]; then
    result="crashed: SIG$(kill -l $((status - 128)) 2>/dev/null || echo $((status - 128)))"
  else
    result="failed: exit $status" code=1
  fi
fi
echo "sandbox: $result"
exit $code
