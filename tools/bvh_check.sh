#!/usr/bin/env bash
# Step 04's correctness check: every builder's nearest hit against brute force over all
# triangles (same triangle, or the same t where triangles share the hit point), on N rays
# of each kind (primary, diffuse, random; peer-bench's make_rays.py) for every mesh in the
# meshes folder, plus rays aimed at shared edges and vertices of the closed meshes.
# Brute force is slow (rays x triangles tests): it runs on every core.
#   usage: tools/bvh_check.sh [N=100489] [MESH_DIR=/work/shared/data/meshes] [PROGRAM]
# Prints one JSON line per mesh and kind; exits 1 when any ray differs or cracks.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
n=${1:-100489}  # 317 x 317: primary rays come as a square image
meshes=${2:-/work/shared/data/meshes}
program=${3:-$root/build/release/steps/04_bvh/04_bvh}
make_rays=/work/shared/tools/peer-bench/make_rays.py
work=$(mktemp -d /tmp/boxes-bvh-check-XXXXXX)
trap 'rm -rf "$work"' EXIT
status=0
for obj in "$meshes"/*.obj; do
  name=$(basename "$obj" .obj)
  for kind in primary diffuse random; do
    extra=()
    [[ $name == oa_thor && $kind == primary ]] &&
      extra=(--eye 960,-384,2 --look 960,600,2 --up 0,0,1 --fov 90)  # the inside camera
    /usr/bin/python3 "$make_rays" "$obj" "$kind" "$n" "$work/rays.bin" "${extra[@]}" >/dev/null
    cracks=()
    [[ $kind == primary && ($name == bunny || $name == sh1) ]] && cracks=(--cracks "$n")
    line=$("$program" check --mesh "$obj" --rays "$work/rays.bin" --threads 0 "${cracks[@]}" 2>/dev/null) ||
      status=1
    echo "{\"kind\":\"$kind\",${line#\{}"
  done
done
exit $status
