#!/usr/bin/env bash
# Installs the Debian packages a workbook command needs, when they are missing.
# usage: tools/deps.sh GROUP...   (groups: build test report slides fuzz grade bench watch)
# As root it runs apt-get; otherwise it prints the exact apt-get line and exits 1.
# The group slides also installs the slides' npm packages (Marp, playwright-core) with
# `npm ci --prefix slides` from slides/package-lock.json when they are missing or stale.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

pkgs_for() {
  case "$1" in
  build)
    echo g++ cmake ninja-build pkg-config libglm-dev libsdl2-dev doctest-dev libstb-dev \
      libtinyobjloader-dev libcli11-dev libimgui-dev nlohmann-json3-dev libgl-dev \
      libegl1 libgl1-mesa-dri
    ;;
  test) echo python3 python3-yaml xvfb xauth ;; # xvfb: the windows' X11 + GLX test
  report) echo python3 python3-matplotlib ;;
  watch) echo inotify-tools ;; # ./workbook check --watch (it polls without)
  slides)
    echo chromium
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
  bench) echo libbenchmark-dev libembree-dev python3-numpy linux-perf ;; # perf: step 05 README
  *)
    echo "tools/deps.sh: unknown group '$1'" >&2
    exit 2
    ;;
  esac
}

slides_npm() { # npm ci --prefix slides, when the group slides is asked for and the lock is newer
  [[ " $* " == *" slides "* ]] || return 0
  local stamp=$root/slides/node_modules/.package-lock.json
  [[ -f $stamp && ! $root/slides/package-lock.json -nt $stamp ]] && return 0
  echo "[deps] npm ci --prefix slides (Marp and playwright-core, pinned in slides/package-lock.json)" >&2
  if ! npm ci --prefix "$root/slides" --no-audit --no-fund >/tmp/boxes-npm.log 2>&1; then
    echo "[deps] npm ci failed; see /tmp/boxes-npm.log" >&2
    tail -5 /tmp/boxes-npm.log >&2
    exit 1
  fi
}

wanted=()
for group in "$@"; do
  for p in $(pkgs_for "$group"); do wanted+=("$p"); done
done

missing=()
for p in "${wanted[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done
# de-duplicate while keeping order
mapfile -t missing < <(printf '%s\n' "${missing[@]}" | awk 'NF && !seen[$0]++')
if [[ ${#missing[@]} -eq 0 ]]; then
  slides_npm "$@"
  exit 0
fi

line="apt-get install -y --no-install-recommends ${missing[*]}"
if [[ $(id -u) -ne 0 ]]; then
  echo "Missing Debian packages. Run as root:" >&2
  echo "  apt-get update && $line" >&2
  exit 1
fi
echo "[deps] installing: ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
if ! apt-get install -y --no-install-recommends "${missing[@]}" >/tmp/boxes-apt.log 2>&1; then
  apt-get update >>/tmp/boxes-apt.log 2>&1
  apt-get install -y --no-install-recommends "${missing[@]}" >>/tmp/boxes-apt.log 2>&1 || {
    echo "[deps] apt-get failed; see /tmp/boxes-apt.log" >&2
    tail -5 /tmp/boxes-apt.log >&2
    exit 1
  }
fi
slides_npm "$@"
