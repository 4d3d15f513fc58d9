# A Debian package of what `cmake --install` installs: `cpack -G DEB` in a build directory writes
# tilesplat_<version>_<arch>.deb, installed under /usr. Build it from a shared build
# (-DBUILD_SHARED_LIBS=ON): dpkg-shlibdeps then derives the runtime dependencies (Vulkan loader,
# OpenEXR, libpng, zlib, zstd, libwebp, libzip, ...) from what libtilesplat.so and the apps link.
# The headers and CMake package need the Vulkan headers, which libvulkan-dev brings.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME tilesplat)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "tilesplat")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
set(CPACK_PACKAGE_DESCRIPTION "A C++20 engine that renders 3D Gaussian Splatting scenes with Vulkan compute \
shaders: the library, its headers, CMake package and pkg-config file, and the apps (tilesplat-render, \
tilesplat-bench, tilesplat-info and, when built, tilesplat-viewer).")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "tilesplat developers <tilesplat@localhost>")
set(CPACK_DEBIAN_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "libvulkan-dev")
if(NOT BUILD_SHARED_LIBS)
  # A static library's users link its dependencies themselves: their development packages.
  string(APPEND CPACK_DEBIAN_PACKAGE_DEPENDS
         ", libopenexr-dev, libpng-dev, zlib1g-dev, libzstd-dev, libwebp-dev, libzip-dev")
endif()
include(CPack)
