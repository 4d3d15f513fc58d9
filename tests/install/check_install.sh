#!/usr/bin/env bash
# What CI checks of tilesplat as a library others install and link:
#   - `cmake --install` of a static and of a shared build into prefixes that are then moved (the
#     install is relocatable), each used by both examples through find_package(tilesplat 0.3);
#   - one example built through pkg-config (static);
#   - the shared library exporting only the tilesplat:: API (nm -D), with its SONAME;
#   - a consumer using add_subdirectory, with no C++ standard of its own, building no tilesplat tests;
#   - every example's image equal, to the bit, to tilesplat-render's of the same view;
#   - a Debian package (cpack -G DEB) of the shared build, installed with apt-get and used by an
#     example built against /usr, then removed (as root, which CI is, or through sudo): where it cannot
#     be installed (no root, or another tilesplat installed), the check fails;
#   - the example sort strategy (examples/custom_sort) built against each install, as a program that
#     checks itself against the built-in radix sort and as a plugin of the installed tilesplat-bench.
# usage: tests/install/check_install.sh BUILD_DIR   (a built static build with tests, as .ci/run makes)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=$(cd "${1:?usage: check_install.sh BUILD_DIR}" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
jobs=${TILESPLAT_JOBS:-2}

scene=$root/scenes/playbot_lod3/playbot_lod3_31000_sh2.ply
cameras=$root/scenes/playbot_lod3/playbot_lod3_31000_sh2.json
compare=$build/tests/tilesplat_compare_exr
"$build/apps/tilesplat-render" "$scene" --cameras "$cameras" --view 1 --width 320 --height 180 \
  -o "$work/expected.exr" >/dev/null 2>&1

configure() { cmake -G Ninja -DCMAKE_BUILD_TYPE=Release "$@" >"$work/configure.log" 2>&1 || { cat "$work/configure.log"; return 1; }; }
# Builds quietly, but a failed build shows the compiler's output (the last 200 lines of it).
build() {
  local dir=$1 log="$work/build-$(basename "$1").log"
  cmake --build "$dir" -j"$jobs" >"$log" 2>&1 || {
    echo "building $dir failed:"
    tail -n 200 "$log"
    return 1
  }
}

# Builds and runs both examples against the package in $1, and compares their images.
check_examples() {
  local prefix=$1 label=$2
  for example in render_exr vulkan_host; do
    configure -S "$root/examples/$example" -B "$work/$label-$example" -DCMAKE_PREFIX_PATH="$prefix"
    build "$work/$label-$example"
    "$work/$label-$example/$example" "$scene" "$cameras" 1 320 180 "$work/$label-$example.exr"
    "$compare" "$work/expected.exr" "$work/$label-$example.exr"
  done
}

# Builds examples/custom_sort against the package in $1, runs its self-check and runs it as a plugin
# of the package's tilesplat-bench (frame benchmark: identical images; sort benchmark: same order).
check_custom_sort() {
  local prefix=$1 label=$2
  configure -S "$root/examples/custom_sort" -B "$work/$label-custom_sort" -DCMAKE_PREFIX_PATH="$prefix"
  build "$work/$label-custom_sort"
  "$work/$label-custom_sort/custom_sort" "$scene" 320 180
  "$prefix/bin/tilesplat-bench" "$scene" --sort-plugin "$work/$label-custom_sort/libserial_radix_sort.so" \
    --sort radix,serial-radix --width 320 --height 180 --warmup 0 --repeat 1 >"$work/plugin-bench.txt" 2>&1
  if grep -q "different images" "$work/plugin-bench.txt"; then cat "$work/plugin-bench.txt"; exit 1; fi
  "$prefix/bin/tilesplat-bench" --sort-bench --sort-plugin "$work/$label-custom_sort/libserial_radix_sort.so" \
    --sort serial-radix --sort-sizes 16 --key-bits 32,64 --warmup 0 --repeat 1 >/dev/null
  echo "serial-radix plugin in $label tilesplat-bench: identical images, exact order"
}

echo "== static library: install, move, find_package =="
cmake --install "$build" --prefix "$work/installed-static" >/dev/null
mv "$work/installed-static" "$work/static"
check_examples "$work/static" static
check_custom_sort "$work/static" static

echo "== static library through pkg-config =="
flags=$(PKG_CONFIG_PATH="$work/static/lib/pkgconfig" pkg-config --cflags --libs --static tilesplat)
echo "pkg-config --cflags --libs --static tilesplat: $flags"
# shellcheck disable=SC2086  # the flags are words
c++ -std=c++20 -O2 "$root/examples/render_exr/main.cpp" -o "$work/pkg-config-render_exr" $flags
"$work/pkg-config-render_exr" "$scene" "$cameras" 1 320 180 "$work/pkg-config.exr"
"$compare" "$work/expected.exr" "$work/pkg-config.exr"

echo "== shared library: build, install, move, find_package =="
# Position-independent as .ci/run's build is, whose objects ccache then reuses; built inside the checkout
# (build-install-shared/, ignored by git) so that ccache, whose base directory is the checkout, finds the
# same relative paths from one clone to the next.
shared_build="$root/build-install-shared"
rm -rf "$shared_build"
configure -S "$root" -B "$shared_build" -DBUILD_SHARED_LIBS=ON -DTILESPLAT_BUILD_TESTS=OFF \
  -DTILESPLAT_BUILD_VIEWER=OFF -DCMAKE_POSITION_INDEPENDENT_CODE=ON
build "$shared_build"
cmake --install "$shared_build" --prefix "$work/installed-shared" >/dev/null
mv "$work/installed-shared" "$work/shared"
check_examples "$work/shared" shared
check_custom_sort "$work/shared" shared
library=$(ls "$work"/shared/lib/libtilesplat.so.*.*.*)
soname=$(objdump -p "$library" | awk '/SONAME/ { print $2 }')
exported=$(nm -D --defined-only -C "$library" | cut -d' ' -f3-)
foreign=$(grep -v -E '^(tilesplat::|typeinfo for tilesplat::|typeinfo name for tilesplat::|vtable for tilesplat::)' \
  <<<"$exported" || true)
echo "$(basename "$library"): SONAME $soname, $(wc -l <<<"$exported") exported symbols"
[[ $soname == libtilesplat.so.$(cut -d. -f3 <<<"$(basename "$library")") ]] || { echo "bad SONAME"; exit 1; }
if [[ -n $foreign ]]; then
  echo "exported outside the tilesplat:: API:"
  echo "$foreign"
  exit 1
fi
"$work/shared/bin/tilesplat-render" --version

echo "== Debian package: cpack, apt-get install, an example against /usr =="
(cd "$shared_build" && cpack -G DEB >"$work/cpack.log" 2>&1) || { cat "$work/cpack.log"; exit 1; }
deb=$(ls "$shared_build"/tilesplat_*.deb)
echo "$(basename "$deb"): $(dpkg-deb -f "$deb" Depends)"
# The check is of the package installed: where it cannot be installed, the check fails (it never passes
# on a package it did not install and use).
SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  sudo -n true 2>/dev/null || { echo "cannot install $deb: not root, and no sudo without a password"; exit 1; }
  SUDO="sudo -n"
fi
version=$(dpkg-deb -f "$deb" Version)
if installed=$(dpkg-query -W -f='${Status} ${Version}' tilesplat 2>/dev/null) && [[ $installed == "install ok installed"* ]]; then
  # This check's own package left by a run that was killed before its cleanup: removed, then installed
  # anew. Any other tilesplat is someone's: the check will not replace it.
  if [[ ${installed##* } != "$version" ]]; then
    echo "cannot install $deb: tilesplat ${installed##* } is installed on this machine (remove it first)"
    exit 1
  fi
  echo "removing tilesplat $version left installed by an earlier check"
  $SUDO apt-get purge -y -qq tilesplat >/dev/null
fi
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "$deb" >"$work/apt.log" 2>&1 || { cat "$work/apt.log"; exit 1; }
# Purged on any failure below too (|| true: under set -e a failing trap command sets the exit status).
trap '$SUDO apt-get purge -y -qq tilesplat >/dev/null 2>&1 || true; rm -rf "$work"' EXIT
tilesplat-render --version
configure -S "$root/examples/render_exr" -B "$work/deb-render_exr"  # no prefix path: the package in /usr
build "$work/deb-render_exr"
ldd "$work/deb-render_exr/render_exr" | grep libtilesplat
"$work/deb-render_exr/render_exr" "$scene" "$cameras" 1 320 180 "$work/deb.exr"
"$compare" "$work/expected.exr" "$work/deb.exr"
$SUDO apt-get purge -y -qq tilesplat >/dev/null
trap 'rm -rf "$work"' EXIT
echo "package installed, used and removed"

echo "== public headers include no OpenEXR, glm or JSON, and Vulkan only in vulkan_interop.h =="
# (sort_strategy.h, the extension point for GPU sorts, reaches Vulkan through vulkan_interop.h.)
# Every public header of the source tree must have been installed: a glob that matched nothing would
# let the grep below pass.
installed_headers=$(find "$work/shared/include/tilesplat" -name '*.h' | wc -l)
source_headers=$(find "$root/engine/include/tilesplat" -name '*.h' | wc -l)
if [ "$installed_headers" -lt "$source_headers" ] || [ "$source_headers" -eq 0 ]; then
  echo "installed $installed_headers public headers, the source tree has $source_headers"
  exit 1
fi
if grep -n -E '#include <(Imf|Iex|OpenEXR|glm|nlohmann|vulkan)' "$work"/shared/include/tilesplat/*.h |
  grep -v 'vulkan_interop.h:.*<vulkan/vulkan.h>'; then
  echo "a public header includes a dependency's header"
  exit 1
fi

echo "== add_subdirectory consumer, no C++ standard of its own =="
# Built inside the checkout (build-install-subproject/, ignored by git), as the shared build above is: the
# consumer compiles the whole engine, and ccache finds it again in the next clone only under the same
# relative paths (a folder of mktemp's would make every run a cold build, 200 s on 2 cores).
subproject_build="$root/build-install-subproject"
rm -rf "$subproject_build"
configure -S "$root/tests/install/subproject" -B "$subproject_build" -DTILESPLAT_SOURCE_DIR="$root"
build "$subproject_build"
"$subproject_build/render_exr" "$scene" "$cameras" 1 320 180 "$work/subproject.exr"
"$compare" "$work/expected.exr" "$work/subproject.exr"
echo "install check passed"
