#!/usr/bin/env bash
# Usage: scripts/golden_outputs.sh RAYSIFT_EXE OUTDIR > hashes.txt
# Renders every command on the bundled scenes at small sizes and prints a hash per deterministic output (sha256 of
# files, SHA-1 of EXR pixels, stats without timings), so two builds can be compared with diff: how arch-lib checked
# that each unification kept outputs bit-identical.
set -euo pipefail
exe=$(readlink -f "$1"); repo=$(cd "$(dirname "$0")/.." && pwd); out=$2
rm -rf "$out"; mkdir -p "$out"; out=$(cd "$out" && pwd); cd "$out"
d=$repo/datasets
r() { "$exe" "$@" --quiet >/dev/null 2>"$out/err.txt" || { echo "FAILED: $*"; cat "$out/err.txt"; exit 1; }; }
for s in engine_ct mri_head; do
  r render --scene $d/${s}_scene.json --width 160 --height 120 -o ${s}_full.exr
  r render --scene $d/${s}_scene.json --width 160 --height 120 --shading phong -o ${s}_full_phong.png
  r render --scene $d/${s}_scene.json --width 160 --height 120 --mode prioritized --ray-fraction 0.3 -o ${s}_prio.exr
  r render --scene $d/${s}_scene.json --width 160 --height 120 --mode prioritized --ray-fraction 0.3 --features none -o ${s}_prio_none.exr
  r render --scene $d/${s}_scene.json --width 160 --height 120 --mode subsample --ray-fraction 0.3 -o ${s}_sub.exr
  r compare ${s}_full.exr ${s}_prio.exr --map ${s}_flipmap.png --stats ${s}_compare.json
  r saliency ${s}_full_phong.png -o ${s}_sal.exr
  r mesh $d/${s}.vdb --tf $d/${s}_tf.json -o ${s}_mesh.ply
  r lines ${s}_mesh.ply --camera $d/${s}_camera.json -o ${s}_lines.png --importance ${s}_imp.exr --svg ${s}_lines.svg
done
r make-scene blocks4 -o b4.ply
r make-scene grass --triangles 2000 -o grass.ply
r render --scene $d/engine_ct_scene.json --width 96 --height 80 --jitter -o jitter.exr
r make-volume blobs --dims 32,32,32 -o blobs.vdb
r info blobs.vdb --stats blobs_info.json
rm blobs.vdb
r nrr b4.ply --views b4.views.json --mode nrr-pixel --resolution 96 -o nrr_pixel --stats nrr_pixel.json
r nrr b4.ply --views b4.views.json --mode peel --redundancy visibility --resolution 96 -o nrr_peel --stats nrr_peel.json
echo '{"center": [0, 8, 0], "edge_u": [2, 0, 0], "edge_v": [0, 0, 2]}' > light.json
for m in raytrace shadowmap conventional nrr peel; do
  r shadows b4.ply --light light.json --method $m --reference raytrace --light-samples 4 --resolution 96 --width 96 --height 80 -o sh_$m.exr --error-map sh_${m}_err.png --stats sh_$m.json
done
rm -f err.txt
# stats: drop timings, keep everything else
for j in *.json; do /usr/bin/python3 - "$j" <<'PY'
import json,sys
p=sys.argv[1]; d=json.load(open(p))
def strip(x):
    if isinstance(x,dict): return {k:strip(v) for k,v in x.items() if k not in ('times_ms','timings_ms','ms','frame_ms','stages')}
    if isinstance(x,list): return [strip(v) for v in x]
    return x
json.dump(strip(d),open(p,'w'),sort_keys=True)
PY
done
find . -type f ! -name "*.exr" | sort | xargs sha256sum
# EXR headers carry a DateTime: hash the pixels (all subimages and channels)
for f in $(find . -name "*.exr" | sort); do echo "$(iinfo --hash -a "$f" | grep -o "SHA-1: [0-9A-F]*" | tr "\n" " ") $f"; done
