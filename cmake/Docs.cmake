# The API reference: `cmake --build build --target docs` runs Doxygen over the public headers,
# docs/api.md and docs/embedding.md into build/docs/api/html. The target exists when Doxygen is
# installed (cmake/setup-deps.sh installs it); it fails on any warning, an undocumented public
# symbol included (docs/Doxyfile.in), and the test ApiDocs.Build runs it with a symbol left
# undocumented to show that it does.
find_package(Doxygen QUIET)
if(NOT DOXYGEN_FOUND)
  message(STATUS "Doxygen not found: no docs target (cmake/setup-deps.sh installs it)")
  return()
endif()
set(TILESPLAT_DOCS_OUTPUT ${PROJECT_BINARY_DIR}/docs/api)
set(TILESPLAT_GENERATED_INCLUDE ${PROJECT_BINARY_DIR}/engine/include)  # version.h
set(TILESPLAT_DOXYFILE ${PROJECT_BINARY_DIR}/docs/Doxyfile)
configure_file(${PROJECT_SOURCE_DIR}/docs/Doxyfile.in ${TILESPLAT_DOXYFILE} @ONLY)
add_custom_target(docs
  COMMAND ${CMAKE_COMMAND} -E make_directory ${TILESPLAT_DOCS_OUTPUT}
  COMMAND ${DOXYGEN_EXECUTABLE} ${TILESPLAT_DOXYFILE}
  COMMENT "Doxygen: the API reference into ${TILESPLAT_DOCS_OUTPUT}/html"
  VERBATIM)

if(TILESPLAT_BUILD_TESTS)
  add_test(NAME ApiDocs.CompleteAndEnforced
           COMMAND bash ${PROJECT_SOURCE_DIR}/tests/docs/check_docs.sh ${TILESPLAT_DOXYFILE})
endif()
