#!/usr/bin/env bash
# Step 04's correctness check: every builder's nearest hit against brute force over all
# triangles (same triangle, or the same t where triangles share the hit point), on N rays
# of each kind (primary, diffuse, random; peer-bench's make_rays.py) for every mesh in the
# meshes folder, plus rays aimed at shared edges and vertices of the closed meshes.
# Brute force is slow (rays x triangles tests): it runs on every core.
#   usage: tools/bench/bvh_check.sh [N=100489] [MESH_DIR=$BOXES_MESHES] [PROGRAM]
# make_rays.py comes from peer-bench, the Embree harness: BOXES_PEER_BENCH names its folder.
# Prints one JSON line per mesh and kind; exits 1 when any ray differs or cracks.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
n=${1:-100489}  # 317 x 317: primary rays come as a square image
meshes=${2:-${BOXES_MESHES:-}}
program=${3:-$root/build/release/steps/04_bvh/04_bvh}
[[ -n $meshes ]] || { echo "bvh_check.sh: no meshes folder: pass MESH_DIR (the second argument) or set BOXES_MESHES" >&2; exit 2; }
[[ -d $meshes ]] || { echo "bvh_check.sh: meshes folder $meshes: no such folder" >&2; exit 2; }
[[ -n ${BOXES_PEER_BENCH:-} ]] || { echo "bvh_check.sh: no peer-bench (for make_rays.py): set BOXES_PEER_BENCH to its folder" >&2; exit 2; }
make_rays=$BOXES_PEER_BENCH/make_rays.py
[[ -f $make_rays ]] || { echo "bvh_check.sh: BOXES_PEER_BENCH=$BOXES_PEER_BENCH has no make_rays.py" >&2; exit 2; }
work=$(mktemp -d -t boxes-bvh-check-XXXXXX) # private (TMPDIR or /tmp), removed however it ends
trap 'rm -rf "$work"' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM
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
