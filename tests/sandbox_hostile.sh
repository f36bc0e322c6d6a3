#!/usr/bin/env bash
# Hostile programs through tools/grading/sandbox.sh: each limit reports its reason and nothing
# outside the sandbox changes. Exit 77 (ctest: skipped) where bubblewrap cannot run.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
sandbox=$root/tools/grading/sandbox.sh
# Not under /tmp: the sandbox gives the command a private, empty /tmp.
work=$(mktemp -d /var/tmp/boxes-hostile-XXXXXX)
trap 'rm -rf "$work"' EXIT
if ! bwrap --ro-bind / / --unshare-all true 2>/dev/null; then
  echo "bubblewrap cannot create namespaces here: skipped"
  exit 77
fi
failures=0
expect() {  # expect RESULT NAME SANDBOX-ARGS...
  local want=$1 name=$2
  shift 2
  local got
  got=$("$sandbox" --dir "$work/box-$name" "$@" 2>/dev/null)
  if [[ $got == "sandbox: $want" ]]; then echo "ok: $name -> $want"; else
    echo "FAIL: $name: expected 'sandbox: $want', got '$got'"; failures=$((failures + 1)); fi
}
build() { printf '%s\n' "$2" >"$work/$1.cpp" && g++ -O1 -o "$work/$1" "$work/$1.cpp"; }
build loop 'int main() { volatile unsigned long n = 0; for (;;) ++n; }'
build segv 'int main() { volatile int* p = nullptr; return *p; }'
build bomb '#include <vector>
int main() { std::vector<char*> v; for (;;) { char* p = new char[1 << 24]; for (int i = 0; i < (1 << 24); i += 4096) p[i] = 1; v.push_back(p); } }'
build spew '#include <cstdio>
int main() { FILE* f = std::fopen("big.txt", "w"); char b[65536] = {1}; for (;;) std::fwrite(b, 1, sizeof b, f); }'
build escape '#include <cstdio>
int main(int, char** argv) { FILE* f = std::fopen(argv[1], "w"); if (!f) return 5; std::fputs("pwned", f); std::fclose(f); return 0; }'
# Forks until fork fails (children wait), then exits 7 with the count; 0 past 5,000 (no limit).
build forks '#include <cstdio>
#include <unistd.h>
int main() { for (int n = 0;; ++n) { pid_t p = fork(); if (p == 0) { pause(); _exit(0); }
  if (p < 0) { std::printf("%d\n", n); return 7; } if (n >= 5000) return 0; } }'
build net '#include <arpa/inet.h>
#include <sys/socket.h>
#include <unistd.h>
int main() { int s = socket(AF_INET, SOCK_STREAM, 0); if (s < 0) return 6; sockaddr_in a{}; a.sin_family = AF_INET; a.sin_port = htons(80); inet_pton(AF_INET, "1.1.1.1", &a.sin_addr); return connect(s, (sockaddr*)&a, sizeof a) == 0 ? 0 : 6; }'

outside=$work/outside.txt
echo "untouched" >"$outside"
expect "time limit" loop --time 1 -- "$work/loop"
expect "crashed: SIGSEGV" segv -- "$work/segv"
expect "memory limit" bomb --memory 256 -- "$work/bomb"
expect "output limit" spew --output 4 -- "$work/spew"
expect "failed: exit 5" escape -- "$work/escape" "$outside"
expect "failed: exit 5" escape-home -- "$work/escape" "$root/pwned.txt"
expect "failed: exit 6" net -- "$work/net"
expect "ok" inside -- "$work/escape" inside.txt
expect "output limit" flood --output 1 -- yes flood
expect "failed: exit 7" forks --processes 64 -- "$work/forks"
forked=$(cat "$work/box-forks/stdout.txt" 2>/dev/null)
[[ $forked =~ ^[0-9]+$ && $forked -le 64 ]] || { echo "FAIL: the fork bomb forked '$forked' times under --processes 64"; failures=$((failures + 1)); }
# Even when the grader runs as root the sandbox has no capabilities: it cannot lift its limits.
expect "failed: exit 4" lift -- sh -c 'prlimit --cpu=unlimited:unlimited --pid $$ || exit 4'
[[ $(cat "$outside") == untouched ]] || { echo "FAIL: a file outside the sandbox changed"; failures=$((failures + 1)); }
[[ ! -e $root/pwned.txt ]] || { echo "FAIL: wrote into the source tree"; rm -f "$root/pwned.txt"; failures=$((failures + 1)); }
[[ $(cat "$work/box-inside/inside.txt") == pwned ]] || { echo "FAIL: the private folder is not writable"; failures=$((failures + 1)); }
size=$(stat -c %s "$work/box-spew/big.txt")
[[ $size -le $((4 << 20)) ]] || { echo "FAIL: output of $size bytes passed the 4 MiB limit"; failures=$((failures + 1)); }
echo "$failures failure(s)"
[[ $failures -eq 0 ]]
