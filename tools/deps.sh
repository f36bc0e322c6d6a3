#!/usr/bin/env bash
# Installs the Debian packages a workbook command needs, when they are missing.
# usage: tools/deps.sh GROUP...   (groups: build test report slides fuzz grade bench watch, or all)
# As root, the group build also installs the compiler cache (ccache), which no command needs.
# As root it runs apt-get; otherwise it prints what an administrator runs once (the packages
# are the machine's, for every user) and exits 1. Its logs are private temporary files,
# removed when it ends, whatever the outcome: several users may run it at once.
# The group slides also installs the slides' npm packages (Marp, playwright-core) with
# `npm ci` in slides/ from slides/package-lock.json when they are missing or stale.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
groups=(build test report slides fuzz grade bench watch)

logs=""
cleanup() { [[ -z $logs ]] || rm -rf "$logs"; }
trap cleanup EXIT
trap 'exit 130' INT # exit, so the EXIT trap removes the logs
trap 'exit 143' TERM
open_log() { # NAME: log=a private log file, in a folder of mktemp's (under TMPDIR or /tmp, mode 0700)
  [[ -n $logs ]] || logs=$(mktemp -d -t boxes-deps-XXXXXX)
  log=$logs/$1
}
failed() { # what, log: the log's last lines (the log itself goes with this command)
  echo "[deps] $1 failed; its last lines:" >&2
  tail -20 "$2" >&2
  exit 1
}

pkgs_for() {
  case "$1" in
  build)
    echo g++ cmake ninja-build pkg-config libglm-dev libsdl2-dev doctest-dev libstb-dev \
      libtinyobjloader-dev libcli11-dev libimgui-dev nlohmann-json3-dev libgl-dev \
      libegl1 libgl1-mesa-dri
    ;;
  # xvfb: the windows' X11 + GLX test; libembree-dev: the bench harness's test (9 MB)
  test) echo python3 python3-yaml xvfb xauth libembree-dev ;;
  report) echo python3 python3-matplotlib ;;
  watch) echo inotify-tools ;; # ./workbook check --watch (it polls without)
  slides)
    echo chromium python3-matplotlib # the decks' plots are tools/plots.py's, as on the report page
    command -v node >/dev/null 2>&1 || echo nodejs npm # Debian's Node.js only when none is installed
    ;;
  fuzz) echo clang libclang-rt-dev python3-hypothesis ;;
  # grade: the grader and its build (no window: the grading tree is configured with
  # BOXES_WINDOW=OFF). Every name exists on Debian 12 and on Ubuntu 22.04 and 24.04 (universe),
  # so Gradescope's setup.sh installs this group alone.
  grade)
    echo bubblewrap python3 g++ cmake ninja-build pkg-config libglm-dev doctest-dev libstb-dev \
      libtinyobjloader-dev libcli11-dev nlohmann-json3-dev
    ;;
  # openfoam-examples, openarena-088-data: the motorbike and the interior map
  # (tools/bench/meshes.py); perf: step 05 README; libgl1-mesa-dri (Mesa's llvmpipe),
  # libegl1 and libegl-mesa0 (EGL, through SDL's offscreen driver): the rasterizer row's
  # OpenGL (tools/bench/raster_gl)
  bench)
    echo libbenchmark-dev libembree-dev openfoam-examples openarena-088-data linux-perf \
      libgl1-mesa-dri libegl1 libegl-mesa0
    ;;
  all) for g in "${groups[@]}"; do pkgs_for "$g"; done ;;
  *)
    echo "tools/deps.sh: unknown group '$1'" >&2
    exit 2
    ;;
  esac
}

# Installed with a group when this runs as root, never required: without them the commands
# work as before (an ordinary user is not asked for them).
optional_for() {
  case "$1" in
  build | all) echo ccache ;; # the compiler cache: the CMake files use it where it is installed
  esac
}

# npm ci run inside slides/, not with --prefix: --prefix also moves npm's machine-wide
# settings file ({prefix}/etc/npmrc), so a lab's proxy, CA file or registry mirror there
# would be ignored.
slides_npm() { # npm ci in slides/, when the group slides is asked for and the lock is newer
  [[ " $* " == *" slides "* ]] || return 0
  local stamp=$root/slides/node_modules/.package-lock.json
  [[ -f $stamp && ! $root/slides/package-lock.json -nt $stamp ]] && return 0
  echo "[deps] npm ci in slides/ (Marp and playwright-core, pinned in slides/package-lock.json)" >&2
  open_log npm.log
  (cd "$root/slides" && npm ci --no-audit --no-fund) >"$log" 2>&1 || failed "npm ci in slides/" "$log"
}

wanted=()
for group in "$@"; do
  pkgs_for "$group" >/dev/null || exit 2 # an unknown group (inside $(...) below its exit is lost)
  for p in $(pkgs_for "$group"); do wanted+=("$p"); done
done

missing=()
for p in "${wanted[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done
if [[ $(id -u) -eq 0 ]]; then
  for group in "$@"; do
    for p in $(optional_for "$group"); do
      status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
      [[ "$status" == "install ok installed" ]] || missing+=("$p")
    done
  done
fi
# de-duplicate while keeping order
mapfile -t missing < <(printf '%s\n' "${missing[@]}" | awk 'NF && !seen[$0]++')
if [[ ${#missing[@]} -eq 0 ]]; then
  slides_npm "$@"
  exit 0
fi

if [[ $(id -u) -ne 0 ]]; then
  # An ordinary user (a lab machine's student) cannot install: say what the administrator
  # runs once, from any clone of the workbook.
  {
    echo "[deps] missing Debian packages: ${missing[*]}"
    echo "[deps] an administrator installs them once, for every user of this machine, with"
    echo "  sudo tools/deps.sh $*"
    echo "[deps] (that is: apt-get update && apt-get install -y --no-install-recommends ${missing[*]})"
    echo "[deps] or everything the workbook uses: sudo tools/deps.sh all"
  } >&2
  exit 1
fi
echo "[deps] installing: ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
open_log apt.log
if ! apt-get install -y --no-install-recommends "${missing[@]}" >"$log" 2>&1; then
  apt-get update >>"$log" 2>&1
  apt-get install -y --no-install-recommends "${missing[@]}" >>"$log" 2>&1 || failed "apt-get install" "$log"
fi
slides_npm "$@"
