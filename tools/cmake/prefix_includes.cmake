# cmake -DSOURCE_ROOT=<project root> -DOUTPUT_ROOT=<dir> -DROOTS=engine;stages;io -DFILES=<rel>;... -P prefix_includes.cmake
# Copies each header FILE (relative to SOURCE_ROOT) to OUTPUT_ROOT/mvflow/FILE with mvflow's own
# root-relative includes prefixed ("engine/model/mesh.h" -> "mvflow/engine/model/mesh.h"), so
# that the installed headers need only <prefix>/include on a host's include path and no name of
# ours can collide with a host's own "engine/..." or "io/...". Other includes stay as they are.
# The build runs it per layer (mvflow_layer, tools/cmake/MvflowLayers.cmake); the sources keep
# their root-relative includes.
cmake_minimum_required(VERSION 3.23)
foreach(var SOURCE_ROOT OUTPUT_ROOT ROOTS FILES)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "prefix_includes.cmake: -D${var}=... is missing")
  endif()
endforeach()
list(JOIN ROOTS "|" roots)
foreach(file IN LISTS FILES)
  file(READ "${SOURCE_ROOT}/${file}" text)
  string(REGEX REPLACE "(#[ \t]*include[ \t]*\")(${roots})/" "\\1mvflow/\\2/" text "${text}")
  file(WRITE "${OUTPUT_ROOT}/mvflow/${file}" "${text}")
endforeach()
