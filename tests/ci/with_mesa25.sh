#!/usr/bin/env bash
# Runs a command on the Mesa 25 lavapipe that `bash cmake/setup-deps.sh --mesa25 [DIR]` unpacked (Debian
# bookworm-backports, what users of newer systems have), instead of the system's Mesa 22: the Vulkan
# loader is pointed at its manifest alone, and its libdrm comes first on the library path. Refuses to
# run when the loader would not find that driver, so that a CI step named for Mesa 25 cannot pass on
# Mesa 22.
#
#   bash tests/ci/with_mesa25.sh COMMAND...       (TILESPLAT_MESA25_DIR: default /opt/tilesplat-mesa25)
set -euo pipefail
dir="${TILESPLAT_MESA25_DIR:-/opt/tilesplat-mesa25}"
if [ ! -f "$dir/lvp_icd.json" ]; then
  echo "with_mesa25: $dir/lvp_icd.json not found (run: bash cmake/setup-deps.sh --mesa25 $dir)" >&2
  exit 1
fi
export VK_DRIVER_FILES="$dir/lvp_icd.json" VK_ICD_FILENAMES="$dir/lvp_icd.json"
export LD_LIBRARY_PATH="$dir/root/usr/lib/x86_64-linux-gnu${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
driver=$(vulkaninfo --summary 2>/dev/null | grep -m1 -E '^[[:space:]]*driverInfo' | sed -E 's/.*= *//')
if [[ "$driver" != "Mesa $(cut -d- -f1 "$dir/version")"* ]]; then
  echo "with_mesa25: the loader finds driver '${driver:-none}', not Mesa $(cat "$dir/version")" >&2
  exit 1
fi
echo "with_mesa25: lavapipe $driver ($dir)"
exec "$@"
