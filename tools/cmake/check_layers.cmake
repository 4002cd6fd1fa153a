# cmake -DMANIFEST=<file> -P tools/cmake/check_layers.cmake: the layer check (tools/cmake/MvflowLayers.cmake)
# on the targets and files a manifest lists. The build runs it with the manifest that configuring
# wrote; tests/layers runs it on a planted violation.
cmake_minimum_required(VERSION 3.23)
if(NOT MANIFEST)
  message(FATAL_ERROR "usage: cmake -DMANIFEST=<manifest.cmake> -P check_layers.cmake")
endif()
include(${CMAKE_CURRENT_LIST_DIR}/MvflowLayers.cmake)
set(MVFLOW_LAYER_TARGETS)
include(${MANIFEST})
set(all)
foreach(target IN LISTS MVFLOW_LAYER_TARGETS)
  mvflow_check_layer_files(TARGET ${target} OWN ${MVFLOW_LAYER_${target}_OWN}
    ALLOWED ${MVFLOW_LAYER_${target}_ALLOWED} KNOWN ${MVFLOW_LAYER_KNOWN}
    ROOT ${MVFLOW_LAYER_ROOT} FILES ${MVFLOW_LAYER_${target}_FILES})
  list(APPEND all ${MVFLOW_LAYER_VIOLATIONS})
endforeach()
mvflow_report_layer_violations("${all}")
