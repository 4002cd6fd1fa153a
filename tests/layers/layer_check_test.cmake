# CTest: the layer check (tools/cmake/MvflowLayers.cmake, run by tools/cmake/check_layers.cmake) accepts a
# clean fixture and refuses a planted include across layers, naming the file, the include and the
# layers the file may include. Fixture: tests/layers/fixture (model <- flow, hull; never compiled).
#   cmake -DSOURCE_DIR=<project root> -DWORK_DIR=<scratch folder> -P layer_check_test.cmake
cmake_minimum_required(VERSION 3.23)
set(fixture ${SOURCE_DIR}/tests/layers/fixture)
set(script ${SOURCE_DIR}/tools/cmake/check_layers.cmake)
file(MAKE_DIRECTORY ${WORK_DIR})

# Writes a manifest as mvflow_check_layers does: model, flow (links model), hull (links model).
function(write_manifest path flow_files)
  file(WRITE ${path}
    "set(MVFLOW_LAYER_ROOT \"${fixture}\")\n"
    "set(MVFLOW_LAYER_KNOWN \"engine/model;stages/flow;stages/hull\")\n"
    "set(MVFLOW_LAYER_TARGETS fx_model fx_flow fx_hull)\n"
    "set(MVFLOW_LAYER_fx_model_OWN engine/model)\n"
    "set(MVFLOW_LAYER_fx_model_FILES \"${fixture}/engine/model/base.h\")\n"
    "set(MVFLOW_LAYER_fx_flow_OWN stages/flow)\n"
    "set(MVFLOW_LAYER_fx_flow_ALLOWED engine/model)\n"
    "set(MVFLOW_LAYER_fx_flow_FILES \"${flow_files}\")\n"
    "set(MVFLOW_LAYER_fx_hull_OWN stages/hull)\n"
    "set(MVFLOW_LAYER_fx_hull_ALLOWED engine/model)\n"
    "set(MVFLOW_LAYER_fx_hull_FILES \"${fixture}/stages/hull/carve.h\")\n")
endfunction()

write_manifest(${WORK_DIR}/clean.cmake "${fixture}/stages/flow/step.cpp;${fixture}/stages/flow/step.h")
execute_process(COMMAND ${CMAKE_COMMAND} -DMANIFEST=${WORK_DIR}/clean.cmake -P ${script}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the layer check refused the clean fixture:\n${err}")
endif()

write_manifest(${WORK_DIR}/planted.cmake "${fixture}/stages/flow/step.cpp;${fixture}/stages/flow/planted_violation.cpp")
execute_process(COMMAND ${CMAKE_COMMAND} -DMANIFEST=${WORK_DIR}/planted.cmake -P ${script}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "the layer check accepted a planted include of stages/hull from stages/flow")
endif()
string(REGEX REPLACE "[ \t\r\n]+" " " err_flat "${err}")
foreach(expected
    "layer check: 2 violation(s):"
    "stages/flow/planted_violation.cpp (target fx_flow) includes \"stages/hull/carve.h\" from layer stages/hull, which fx_flow does not link (it may include: stages/flow engine/model)"
    "stages/flow/planted_violation.cpp (target fx_flow) includes \"engine/base.h\": engine is no layer folder")
  string(FIND "${err_flat}" "${expected}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "the layer check's message lacks \"${expected}\":\n${err}")
  endif()
endforeach()
message(STATUS "layer check: clean fixture accepted, planted violations refused")
