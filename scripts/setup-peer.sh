#!/usr/bin/env bash
# One-time set-up of Mitsuba 3, the independent peer of `cargo xtask bench peer`.
#
# - installs Debian's libllvm19 (Mitsuba's `llvm_ad_rgb` variant JIT-compiles through LLVM; Debian 12's
#   own LLVM 15 crashes it). bookworm has 19.1.7 in main; the bookworm-backports suite is tried otherwise;
# - creates a Python virtual environment under ~/.cache/radcache/peer-venv (RADCACHE_PEER_VENV overrides)
#   and installs the `mitsuba` package (and numpy) from PyPI into it;
# - checks that the llvm variant loads and renders a one-pixel scene.
# Idempotent. The bench finds the venv at the same path and sets DRJIT_LIBLLVM_PATH itself.
set -euo pipefail

venv="${RADCACHE_PEER_VENV:-$HOME/.cache/radcache/peer-venv}"
llvm=/usr/lib/x86_64-linux-gnu/libLLVM-19.so.1
sudo_() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

if ! dpkg-query -W -f='${Status}' libllvm19 2>/dev/null | grep -q "install ok installed"; then
  echo "radcache setup-peer: installing libllvm19" >&2
  export DEBIAN_FRONTEND=noninteractive
  sudo_ apt-get update -q
  if ! sudo_ apt-get install -y -q libllvm19; then
    sudo_ apt-get install -y -q -t bookworm-backports libllvm19
  fi
fi
[ -e "$llvm" ] || llvm=$(dpkg -L libllvm19 | grep -m1 'libLLVM.*\.so')

if [ ! -x "$venv/bin/python" ]; then
  echo "radcache setup-peer: creating $venv" >&2
  mkdir -p "$(dirname "$venv")"
  python3 -m venv "$venv"
fi
"$venv/bin/python" -c 'import mitsuba' 2>/dev/null || "$venv/bin/pip" install -q mitsuba numpy

DRJIT_LIBLLVM_PATH="$llvm" "$venv/bin/python" - <<'PY'
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
img = mi.render(mi.load_dict({"type": "scene", "integrator": {"type": "path"}, "sensor": {"type": "perspective",
      "film": {"type": "hdrfilm", "width": 1, "height": 1}}}), spp=1)
print(f"radcache setup-peer: Mitsuba {mi.__version__} (llvm_ad_rgb) works")
PY
echo "radcache setup-peer: done (venv $venv, DRJIT_LIBLLVM_PATH=$llvm)" >&2
