#!/usr/bin/env bash
# Installs the Debian packages tilesplat builds and tests with, only when one is missing.
# Safe to run repeatedly; needs root (or sudo) only when something must be installed.
# zlib, zstd, libwebp and libzip are the containers of the compressed splat formats (.spz, .sog).
# xvfb and xauth give the viewer's tests a display (xvfb-run) on a machine without one.
# doxygen builds the API reference (the docs target and its test); file is what cpack -G DEB asks
# to find the binaries whose library dependencies it lists.
# --fuzz adds clang and its compiler-rt (libFuzzer) for tests/fuzz/run.sh; the normal build needs neither.
# --cluster adds Slurm (slurm-wlm: slurmctld, slurmd, sbatch) and munge for tests/cluster/slurm_test.sh,
# which runs a one-node cluster of its own; nothing is configured or started here.
set -euo pipefail
pkgs=(
  build-essential cmake ninja-build pkg-config
  libvulkan-dev mesa-vulkan-drivers vulkan-validationlayers vulkan-tools
  glslang-tools spirv-tools doxygen file
  libglm-dev libglfw3-dev libopenexr-dev libpng-dev nlohmann-json3-dev
  zlib1g-dev libzstd-dev libwebp-dev libzip-dev
  libgtest-dev googletest
  xvfb xauth
)
case "${1:-}" in
  --fuzz) pkgs+=(clang libclang-rt-dev) ;;
  --cluster) pkgs+=(slurm-wlm munge) ;;
  "") ;;
  *) echo "setup: unknown option '$1' (--fuzz or --cluster)" >&2; exit 2 ;;
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
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
