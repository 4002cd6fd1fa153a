# The installed package (README "Installing and using mvflow from CMake"), after every target is
# defined: mvflow_layer installs each layer library and its prefixed headers, tools/ the mvflow
# program; here the umbrella target, the CMake package (find_package(mvflow)) and the .deb
# (cpack -G DEB). Tests, benchmarks, fuzzers and the Python module are never installed.
include(CMakePackageConfigHelpers)

# mvflow::mvflow: every layer (as COLMAP's colmap::colmap), what a host program links. In a
# superbuild it also gives the prefixed include form, <mvflow/engine/...>, as the installed one.
get_property(mvflow_layers GLOBAL PROPERTY MVFLOW_LAYERS)
add_library(mvflow_library INTERFACE)
add_library(mvflow::mvflow ALIAS mvflow_library)
target_link_libraries(mvflow_library INTERFACE ${mvflow_layers})
target_include_directories(mvflow_library INTERFACE $<BUILD_INTERFACE:${PROJECT_BINARY_DIR}/include>)
set(MVFLOW_COMPONENTS)
foreach(layer IN LISTS mvflow_layers)
  add_dependencies(mvflow_library ${layer}_headers)
  get_target_property(component ${layer} EXPORT_NAME)
  list(APPEND MVFLOW_COMPONENTS ${component})
endforeach()
list(JOIN MVFLOW_COMPONENTS " " MVFLOW_COMPONENTS)
set_target_properties(mvflow_library PROPERTIES EXPORT_NAME mvflow)
install(TARGETS mvflow_library EXPORT mvflowTargets)

set(mvflow_config_dir ${CMAKE_INSTALL_LIBDIR}/cmake/mvflow)
install(EXPORT mvflowTargets NAMESPACE mvflow:: DESTINATION ${mvflow_config_dir})
configure_package_config_file(${CMAKE_CURRENT_LIST_DIR}/mvflowConfig.cmake.in
  ${PROJECT_BINARY_DIR}/mvflowConfig.cmake INSTALL_DESTINATION ${mvflow_config_dir})
# 0.x: a minor version may change the API, so only the same major.minor satisfies a request.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/mvflowConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/mvflowConfig.cmake ${PROJECT_BINARY_DIR}/mvflowConfigVersion.cmake
  DESTINATION ${mvflow_config_dir})

# One .deb, mvflow_<version>_<arch>.deb, with everything installed: the program for cluster
# nodes, the libraries, headers and package for builds. Depends: the runtime libraries the
# program links, as dpkg-shlibdeps finds them (Debian 12: libtbb12, libembree3-3, libopencv-*406,
# libspdlog1.10-fmt9, ...); the -dev packages a find_package(mvflow) build needs are only suggested,
# so that a node that runs mvflow does not install them. Name, version and summary: project()'s.
install(FILES ${PROJECT_SOURCE_DIR}/LICENSE DESTINATION ${CMAKE_INSTALL_DOCDIR})
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_CONTACT "mvflow maintainers <maintainers@users.noreply.h-seed-824040f6.example>")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
find_program(MVFLOW_DPKG_SHLIBDEPS dpkg-shlibdeps)
if(MVFLOW_DPKG_SHLIBDEPS)
  set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
else()
  # What dpkg-shlibdeps gives on Debian 12 (bookworm), for a machine without dpkg-dev.
  set(CPACK_DEBIAN_PACKAGE_DEPENDS "libc6 (>= 2.35), libembree3-3 (>= 3.13.5), libfmt9 (>= 9.1.0), libgcc-s1 (>= 3.0), libopencv-core406 (>= 4.6.0), libopencv-imgcodecs406 (>= 4.6.0), libpng16-16 (>= 1.6.2), libopenmesh1 (>= 9.0), libspdlog1.10-fmt9, libstdc++6 (>= 11), libtbb12 (>= 2021.4.0)")
endif()
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "libeigen3-dev, libtbb-dev, libopenmesh-dev, libopencv-dev, libembree-dev, libspdlog-dev, nlohmann-json3-dev")
include(CPack)
