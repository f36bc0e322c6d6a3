#!/usr/bin/env bash
# Runs one untrusted command isolated and limited (for the grader: student builds and tests).
# usage: tools/grading/sandbox.sh [--time SECONDS] [--memory MB] [--output MB] [--processes N]
#                                 [--dir DIR] [--no-isolation [--user NAME]] -- COMMAND [ARGS...]
# Isolation (bubblewrap): of the machine only the system read-only (/usr, /etc), DIR (default: a
# fresh folder in the clone's build/sandbox/) the only writable place and the working directory,
# the command's program, a private /tmp and /dev/shm, no network, own PID namespace without
# capabilities (as root: a user id of its own), killed with this script. Limits:
# wall-clock seconds, CPU seconds, address space, output and the size of any file written.
# The command's stdout and stderr go to DIR/stdout.txt and DIR/stderr.txt (bounded by the
# output limit). Prints one line "sandbox: RESULT" on stdout: ok | failed: exit N |
# time limit | memory limit | output limit | crashed: SIGNAME. Exit status: 0 ok, 1 failed,
# 3 limit or crash, 2 usage or refused (no user namespaces and no --no-isolation).
# --user NAME (with --no-isolation, as root): the command runs as that unprivileged user,
# and every process of that user is killed when it ends.
# The one implementation is sandbox.py beside this (the grader imports it); this is its
# wrapper. It runs in the caller's folder (DIR and the command's paths are the caller's), so
# the tools package is put on Python's path here, and only it (-I: not the caller's folder).
tree=$(cd "$(dirname "$0")/../.." && pwd)
exec /usr/bin/python3 -I -c 'import sys; sys.path.insert(0, sys.argv.pop(1))
from tools.grading.sandbox import main
sys.exit(main(sys.argv[1:]))' "$tree" "$@"
