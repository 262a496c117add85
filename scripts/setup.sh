#!/usr/bin/env bash
# One-time set-up of a fresh Debian 12 (bookworm) machine for radcache.
#
# - adds the bookworm-backports suite and installs Mesa 25 (lavapipe with VK_KHR_ray_query) from it;
# - installs the Vulkan loader, the Khronos validation layer, spirv-tools (spirv-val) and the
#   tools the `shaderc` crate needs to build glslang/SPIRV-Tools from source (cmake, ninja, g++, python3);
# - installs fonts-dejavu-core (DejaVu Sans: the text of `radcache convergence`'s PNG plot);
# - checks for a Rust toolchain.
# Idempotent: a machine that already has everything is left as it is (a quick check, no apt call).
set -euo pipefail

need_pkgs=(libvulkan1 vulkan-tools vulkan-validationlayers spirv-tools glslang-tools build-essential cmake ninja-build python3 git pkg-config fonts-dejavu-core)

have_all() {
  for p in "${need_pkgs[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || return 1
  done
  # lavapipe must come from backports (Mesa >= 25): Debian 12's own Mesa 22.3 has no ray query.
  local v
  v=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
  [[ "$v" == 25.* ]] || return 1
  return 0
}

sudo_() { if [ "$(id -u)" = 0 ]; then "$@"; else sudo "$@"; fi; }

if ! have_all; then
  echo "radcache setup: installing system packages (bookworm-backports Mesa, Vulkan, validation layer)" >&2
  list=/etc/apt/sources.list.d/radcache-backports.sources
  if ! grep -rqs 'bookworm-backports' /etc/apt/sources.list /etc/apt/sources.list.d/; then
    sudo_ tee "$list" >/dev/null <<'SRC'
Types: deb
URIs: http://deb.debian.org/debian
Suites: bookworm-backports
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SRC
  fi
  export DEBIAN_FRONTEND=noninteractive
  sudo_ apt-get update -q
  sudo_ apt-get install -y -q -t bookworm-backports mesa-vulkan-drivers
  sudo_ apt-get install -y -q "${need_pkgs[@]}"
fi

if ! command -v cargo >/dev/null 2>&1; then
  if [ -x "$HOME/.cargo/bin/cargo" ]; then
    export PATH="$HOME/.cargo/bin:$PATH"
  else
    echo "radcache setup: no Rust toolchain found; install one with rustup (https://rustup.rs), Rust >= 1.85" >&2
    exit 1
  fi
fi

# fmt and clippy are part of CI.
if command -v rustup >/dev/null 2>&1; then
  rustup component list --installed 2>/dev/null | grep -q '^clippy' || rustup component add clippy rustfmt
fi
