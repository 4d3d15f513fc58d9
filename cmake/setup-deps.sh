#!/usr/bin/env bash
# Installs the Debian packages tilesplat builds and tests with, only when one is missing.
# Safe to run repeatedly; needs root (or sudo) only when something must be installed.
# zlib, zstd, libwebp and libzip are the containers of the compressed splat formats (.spz, .sog).
# libssl-dev's libcrypto gives the apps SHA-256 (the EXRs' scene checksum, the render manifest).
# xvfb and xauth give the viewer's tests a display (xvfb-run) on a machine without one.
# python3-dev and python3-venv build and test the Python package; python3-torch (Debian's CPU build) runs
# gsplat's PyTorch functions, which python/run_tests.sh holds tilesplat.rasterization() to.
# doxygen builds the API reference (the docs target and its test); file is what cpack -G DEB asks
# to find the binaries whose library dependencies it lists. ccache lets .ci/run compile the engine once
# for the build, the Python wheel and the installed shared library (the build itself does not need it).
# --fuzz adds clang and its compiler-rt (libFuzzer) for tests/fuzz/run.sh; the normal build needs neither.
# --cluster adds Slurm (slurm-wlm: slurmctld, slurmd, sbatch) and munge for tests/cluster/slurm_test.sh,
# which runs a one-node cluster of its own; nothing is configured or started here.
# --mesa25 [DIR] unpacks the Mesa 25 lavapipe of Debian bookworm-backports (mesa-vulkan-drivers 25.0.7
# and the libdrm it needs) into DIR (default /opt/tilesplat-mesa25), beside the system's Mesa 22, and
# writes DIR/lvp_icd.json; tests/ci/with_mesa25.sh runs a command on it. Nothing system-wide changes
# but the bookworm-backports source, which apt ranks below bookworm (priority 100).
set -euo pipefail
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"

mesa25() {
  local dir="${1:-/opt/tilesplat-mesa25}" version="25.0.7-2~bpo12+1"
  if [ -f "$dir/lvp_icd.json" ] && grep -q "$version" "$dir/version" 2>/dev/null; then
    echo "setup: Mesa $version lavapipe present in $dir"
    return 0
  fi
  if ! apt-cache policy mesa-vulkan-drivers | grep -q "$version"; then
    echo "setup: adding the bookworm-backports source"
    printf 'Types: deb\nURIs: http://deb.debian.org/debian\nSuites: bookworm-backports\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' |
      $SUDO tee /etc/apt/sources.list.d/bookworm-backports.sources >/dev/null
    $SUDO apt-get update -qq
  fi
  local debs
  debs=$(mktemp -d)
  chown _apt "$debs" 2>/dev/null || true  # apt downloads as its _apt user where it can write
  (cd "$debs" && apt-get download -q "mesa-vulkan-drivers=$version" libdrm2/bookworm-backports \
    libdrm-amdgpu1/bookworm-backports)
  $SUDO rm -rf "$dir"
  $SUDO mkdir -p "$dir"
  for deb in "$debs"/*.deb; do $SUDO dpkg -x "$deb" "$dir/root"; done
  rm -rf "$debs"
  local lib="$dir/root/usr/lib/x86_64-linux-gnu"
  [ -f "$lib/libvulkan_lvp.so" ] || { echo "setup: $lib/libvulkan_lvp.so missing after unpacking" >&2; return 1; }
  # The package's manifest names the library bare (found on the system's path); this one names ours.
  sed "s|\"library_path\": *\"[^\"]*\"|\"library_path\": \"$lib/libvulkan_lvp.so\"|" \
    "$dir/root/usr/share/vulkan/icd.d/lvp_icd.json" | $SUDO tee "$dir/lvp_icd.json" >/dev/null
  echo "$version" | $SUDO tee "$dir/version" >/dev/null
  echo "setup: Mesa $version lavapipe unpacked into $dir (tests/ci/with_mesa25.sh runs commands on it)"
}

pkgs=(
  build-essential cmake ninja-build pkg-config
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
  glslang-tools spirv-tools doxygen file ccache
  libglm-dev libglfw3-dev libopenexr-dev libpng-dev nlohmann-json3-dev libcli11-dev
  zlib1g-dev libzstd-dev libwebp-dev libzip-dev libssl-dev
  libgtest-dev googletest
  python3-dev python3-venv python3-torch
  xvfb xauth
)
case "${1:-}" in
  --fuzz) pkgs+=(clang libclang-rt-dev) ;;
  --cluster) pkgs+=(slurm-wlm munge) ;;
  --mesa25) mesa25 "${2:-}"; exit ;;
  "") ;;
  *) echo "setup: unknown option '$1' (--fuzz, --cluster or --mesa25 [DIR])" >&2; exit 2 ;;
esac
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#pkgs[@]} packages present"
  exit 0
fi
echo "setup: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
