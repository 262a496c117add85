#!/usr/bin/env bash
# The delivery formats on files nobody in this project wrote: each Khronos sample model of
# ../shared/models (or the .gltf/.glb files given as arguments) is packed by gltfpack as users get
# it (its default: KHR_mesh_quantization; -cc: + EXT_meshopt_compression with its filters), both
# outputs and the original are rendered alike, and each output must match the original within
# relMSE 2e-3 (`radcache compare --max-relmse`). The original rendered with another seed is
# printed beside them as the noise level.
#
# gltfpack comes from the npm registry (installed under ~/.cache/radcache/npm once;
# RADCACHE_GLTFPACK names another binary). Renders are 128², default preset, a constant white
# environment (the models have no light). Exit status 1 when any output misses the bound.
# Usage: scripts/delivery-check.sh [MODEL.gltf|MODEL.glb ...]
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TARGET_DIR="${CARGO_TARGET_DIR:-$HOME/.cache/radcache/target}"
export RADCACHE_VALIDATION="${RADCACHE_VALIDATION:-0}"
export RUST_LOG="${RUST_LOG:-error}"

gltfpack="${RADCACHE_GLTFPACK:-}"
if [ -z "$gltfpack" ]; then
  npm_dir="$HOME/.cache/radcache/npm"
  gltfpack="$npm_dir/node_modules/.bin/gltfpack"
  if [ ! -x "$gltfpack" ]; then
    echo "delivery-check: installing gltfpack into $npm_dir" >&2
    mkdir -p "$npm_dir"
    npm install --prefix "$npm_dir" --no-save --silent gltfpack >&2
  fi
fi

if [ "$#" -gt 0 ]; then
  models=("$@")
else
  models=(../shared/models/DamagedHelmet/glTF-Binary/DamagedHelmet.glb ../shared/models/Suzanne/glTF/Suzanne.gltf)
fi

cargo build -q -p radcache-cli
radcache="$CARGO_TARGET_DIR/debug/radcache"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
render() { "$radcache" render "$1" --resolution 128x128 --env-radiance 1,1,1 --seed "$2" -o "$3" -q; }
relmse() { "$radcache" compare "$1" "$2" --json | python3 -c 'import json,sys; print("%.3g" % json.load(sys.stdin)["metrics"]["relmse"])'; }

status=0
printf '%-24s %-10s %-12s %s\n' model packing relMSE "(noise: original, seed 2)"
for model in "${models[@]}"; do
  name=$(basename "${model%.*}")
  render "$model" 1 "$out/$name.exr"
  render "$model" 2 "$out/$name-seed2.exr"
  noise=$(relmse "$out/$name.exr" "$out/$name-seed2.exr")
  for packing in default cc; do
    flags=()
    [ "$packing" = cc ] && flags=(-cc)
    "$gltfpack" -i "$model" -o "$out/$name-$packing.glb" "${flags[@]}" >/dev/null
    render "$out/$name-$packing.glb" 1 "$out/$name-$packing.exr"
    e=$(relmse "$out/$name.exr" "$out/$name-$packing.exr")
    verdict=ok
    if ! "$radcache" compare "$out/$name.exr" "$out/$name-$packing.exr" --max-relmse 2e-3 >/dev/null; then
      verdict="FAILS (> 2e-3)"
      status=1
    fi
    printf '%-24s %-10s %-12s %s  %s\n' "$name" "$packing" "$e" "$noise" "$verdict"
  done
done
exit "$status"
