#!/usr/bin/env bash
# Step 04's correctness check: every builder's nearest hit against brute force over all
# triangles (same triangle, or the same t where triangles share the hit point), on N rays
# of each kind (primary, diffuse, random; `04_bvh rays`) for every mesh in the meshes
# folders, plus rays aimed at shared edges and vertices of the closed meshes.
# Brute force is slow (rays x triangles tests): it runs on every core.
#   usage: tools/bench/bvh_check.sh [N=100489] [MESH_DIR=$BOXES_MESHES] [PROGRAM]
# Without MESH_DIR: data/meshes/ and the bench's converted meshes (build/meshes/, made by
# ./workbook bench) when they are there.
# Prints one JSON line per mesh and kind; exits 1 when any ray differs or cracks.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
n=${1:-100489}  # 317 x 317: primary rays come as a square image
meshes=${2:-${BOXES_MESHES:-}}
program=${3:-$root/build/release/steps/04_bvh/04_bvh}
folders=("$root/data/meshes")
[[ -d $root/build/meshes ]] && folders+=("$root/build/meshes")
if [[ -n $meshes ]]; then
  [[ -d $meshes ]] || { echo "bvh_check.sh: meshes folder $meshes: no such folder" >&2; exit 2; }
  folders=("$meshes")
fi
work=$(mktemp -d -t boxes-bvh-check-XXXXXX) # private (TMPDIR or /tmp), removed however it ends
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
status=0
objs=()
for folder in "${folders[@]}"; do objs+=("$folder"/*.obj); done
for obj in "${objs[@]}"; do
  name=$(basename "$obj" .obj)
  for kind in primary diffuse random; do
    extra=()
    [[ $name == oa_thor && $kind == primary ]] &&
      extra=(--eye 960,-384,2 --look 960,600,2 --up 0,0,1 --fov 90)  # the inside camera
    "$program" rays --mesh "$obj" --kind "$kind" --count "$n" --out "$work/rays.bin" "${extra[@]}" >/dev/null
    cracks=()
    [[ $kind == primary && ($name == bunny || $name == sh1) ]] && cracks=(--cracks "$n")
    line=$("$program" check --mesh "$obj" --rays "$work/rays.bin" --threads 0 "${cracks[@]}" 2>/dev/null) ||
      status=1
    echo "{\"kind\":\"$kind\",${line#\{}"
  done
done
exit $status
