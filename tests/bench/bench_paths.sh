# Sourced by the scripts of tests/bench: runs from the repository root and sets the paths every one of them
# takes as its first three arguments: build (default build/), scene and cameras (default: the 500k-Gaussian
# playbot of ../shared/scenes, or $TILESPLAT_SHARED_SCENES, with its cameras). require_files NAME FILE...
# stops with an error naming the first that is missing.
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
build="${1:-build}"
shared="${TILESPLAT_SHARED_SCENES:-$(cd .. && pwd)/shared/scenes}"
scene="${2:-$shared/playbot_lod0_500000_sh2.ply}"
cameras="${3:-$shared/cameras/playbot_lod0_500000_sh2.json}"
require_files() {
  local name="$1"
  shift
  for file in "$@"; do
    [ -e "$file" ] || { echo "$name: $file not found" >&2; exit 1; }
  done
}
