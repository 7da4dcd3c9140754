#!/usr/bin/env bash
# Makes scenes/sandstone_shale.msh, the user-mesh example of docs/scene.md ("Several joint sets and materials"):
# the paper's 50 x 100 mm specimen meshed at 1 mm with three horizontal layers 33.3 mm thick, written by
# `rbdem mesh`, then its physical groups renamed as a user would name them in gmsh: the surfaces "sandstone_lower",
# "shale" and "sandstone_upper", the two layer boundaries "bedding".
# Usage: tools/make_sandstone_shale_mesh.sh [build/bin/rbdem]
set -euo pipefail
rbdem=${1:-build/bin/rbdem}
here=$(cd "$(dirname "$0")/.." && pwd)
out="$here/scenes/sandstone_shale.msh"
tmp=$(mktemp --suffix=.msh)
"$rbdem" mesh -q --set joint_set.dip_deg=0 --set joint_set.spacing=0.0333333333333333 \
  --set joint_set.offset=0.0166666666666667 --out "$tmp" >/dev/null
sed -e 's/^1 1 "joint_set"$/1 1 "bedding"/' -e 's/^2 2 "layer_0"$/2 2 "sandstone_lower"/' \
  -e 's/^2 3 "layer_1"$/2 3 "shale"/' -e 's/^2 4 "layer_2"$/2 4 "sandstone_upper"/' "$tmp" >"$out"
rm -f "$tmp"
grep -q '"shale"' "$out" && grep -q '"bedding"' "$out" || { echo "renaming failed: check $out" >&2; exit 1; }
echo "wrote $out"
