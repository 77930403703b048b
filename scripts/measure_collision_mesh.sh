#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The collision mesh of `replay --mesh-out`, from two graspfill binaries
# (before and after a change), on the bundled recording and two zoo objects
# (mug: a handle, a concave spot; bottle: a neck): triangles, Open3D's
# watertight test, the cloud points outside the mesh (p99 and max of their
# distance, inside points as 0; build/bin/mesh_containment, the same
# measure for both), the mesh's surface to the cloud (p95, its --json),
# how it was made and its build time (its --json build_ms), as a
# Markdown table (docs/measurements/2026-12-06-collision-mesh.md).
#   scripts/measure_collision_mesh.sh BEFORE_GRASPFILL AFTER_GRASPFILL MESH_CONTAINMENT DIR [AFTER_FLAGS...]
set -euo pipefail
if [ $# -lt 4 ]; then
  sed -n '2,10p' "$0" >&2
  exit 2
fi
before=$1 after=$2 measure=$3 dir=$4
shift 4
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$dir"
"$after" synth --shape mug --seed 7 -o "$dir/mug" --force > /dev/null
"$after" synth --shape bottle --seed 7 -o "$dir/bottle" --force > /dev/null
echo "| model | build | triangles | watertight | points outside | outside p99 [mm] | outside max [mm] | stated [mm] | mesh to cloud p95 [mm] | method | mesh time [ms] |"
echo "|---|---|---:|---|---:|---:|---:|---:|---:|---|---:|"
for model in default mug bottle; do
  log=$dir/$model/recording.lcmlog
  [ "$model" = default ] && log=$root/replay/default/recording.lcmlog
  for which in before after; do
    bin=$before flags=()
    if [ "$which" = after ]; then bin=$after flags=("$@"); fi
    out=$dir/$model.$which
    "$bin" replay "$log" -o "$out.cloud.ply" --mesh-out "$out.mesh.ply" --no-publish --json --force \
      "${flags[@]}" > "$out.json"
    "$measure" "$out.mesh.ply" "$out.cloud.ply" > "$out.containment.json"
    /usr/bin/python3 - "$model" "$which" "$out.json" "$out.containment.json" <<'PY'
import json, sys
model, which, report, containment = sys.argv[1:]
text = open(report).read()
mesh = json.loads(text[text.index("{"):])["mesh"]
c = json.loads(open(containment).read())
stated = mesh.get("deviation_mm")
print(f"| {model} | {which} | {c['triangles']} | {'yes' if c['watertight'] else 'no'} | "
      f"{c['points_outside']} of {c['points']} | {c['outside_p99_mm']:.2f} | {c['outside_max_mm']:.2f} | "
      f"{'-' if stated is None else f'{stated:.2f}'} | {mesh['surface_to_cloud_mm']['p95']:.2f} | "
      f"{mesh.get('method', 'dense')} | {mesh['build_ms']:.0f} |")
PY
  done
done
