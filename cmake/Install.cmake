# What `cmake --install` puts under the prefix, all of it relocatable (paths relative to the prefix):
#   lib/libtilesplat.a, or lib/libtilesplat.so.MAJOR.MINOR.PATCH with its SONAME link .so.MAJOR
#   include/tilesplat/*.h                          the public API (version.h generated)
#   lib/cmake/tilesplat/                           find_package(tilesplat): config, version, targets
#   lib/pkgconfig/tilesplat.pc                     pkg-config
#   bin/tilesplat-{render,bench,info,viewer}       the apps, when built
#   share/doc/tilesplat/                           LICENSE, README.md
include(CMakePackageConfigHelpers)

set(TILESPLAT_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/tilesplat)

install(TARGETS tilesplat EXPORT tilesplatTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY ${PROJECT_SOURCE_DIR}/engine/include/tilesplat DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h")
install(FILES ${PROJECT_BINARY_DIR}/engine/include/tilesplat/version.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/tilesplat)
install(EXPORT tilesplatTargets NAMESPACE tilesplat:: DESTINATION ${TILESPLAT_CMAKE_DIR})

# The package config finds what the exported target names: Vulkan (its headers are the public
# headers' one dependency), and for a static library the libraries its objects call into.
set(TILESPLAT_SHARED ${BUILD_SHARED_LIBS})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/tilesplatConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/tilesplatConfig.cmake
                              INSTALL_DESTINATION ${TILESPLAT_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/tilesplatConfigVersion.cmake
                                 COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/tilesplatConfig.cmake ${PROJECT_BINARY_DIR}/tilesplatConfigVersion.cmake
        DESTINATION ${TILESPLAT_CMAKE_DIR})

# pkg-config: the prefix is found from the .pc file's own place, so the tree can move. A static
# library lists its dependencies as private, for `pkg-config --static`.
file(RELATIVE_PATH TILESPLAT_PC_TO_PREFIX ${CMAKE_INSTALL_FULL_LIBDIR}/pkgconfig ${CMAKE_INSTALL_PREFIX})
string(REGEX REPLACE "/$" "" TILESPLAT_PC_TO_PREFIX "${TILESPLAT_PC_TO_PREFIX}")
if(BUILD_SHARED_LIBS)
  set(TILESPLAT_PC_REQUIRES_PRIVATE "")
  set(TILESPLAT_PC_LIBS_PRIVATE "")
else()
  set(TILESPLAT_PC_REQUIRES_PRIVATE "Requires.private: OpenEXR libpng zlib libzstd libwebp libzip")
  set(TILESPLAT_PC_LIBS_PRIVATE "Libs.private: -pthread -ldl")
endif()
configure_file(${PROJECT_SOURCE_DIR}/cmake/tilesplat.pc.in ${PROJECT_BINARY_DIR}/tilesplat.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/tilesplat.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# The apps find a shared libtilesplat beside them, relative to their own place, wherever the prefix is.
file(RELATIVE_PATH TILESPLAT_BIN_TO_LIB ${CMAKE_INSTALL_FULL_BINDIR} ${CMAKE_INSTALL_FULL_LIBDIR})
foreach(app tilesplat-render tilesplat-bench tilesplat-info tilesplat-viewer)
  if(TARGET ${app})
    if(BUILD_SHARED_LIBS)
      set_target_properties(${app} PROPERTIES INSTALL_RPATH "$ORIGIN/${TILESPLAT_BIN_TO_LIB}")
    endif()
    install(TARGETS ${app} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  endif()
endforeach()
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
