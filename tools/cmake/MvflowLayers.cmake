# Layers: one folder, one library target. A file may include (root-relative, "engine/model/mesh.h")
# only its own folder and the folders of the layer targets its target links (directly, or through
# a linked target's PUBLIC links). The check runs at configure time and again as part of every
# build (target mvflow_layer_check, which each layer waits for), and stops with an error that names
# the file, the include and the layers that file may include.
#
#   mvflow_layer(<target> [HEADERS h...] SOURCES s... [PUBLIC dep...] [PRIVATE dep...])
#     A static library for the current folder with alias mvflow::<name without "mvflow_">, its
#     headers as a header file set (base: the project root), mvflow_warnings privately. It is
#     installed and exported as mvflow::<name> (tools/cmake/MvflowPackage.cmake), with its
#     headers under include/mvflow/<folder>/, their includes prefixed (prefix_includes.cmake).
#   mvflow_layer_clients(<target>...)
#     Programs and helper libraries outside the layers (tools, tests, perf, fuzz) that the check
#     covers too: their own folder plus the layers they link.
#   mvflow_check_layers()
#     After every target is defined: checks the layers and their clients and sets up the
#     build-time check.
#   mvflow_check_layer_files(TARGET t OWN folder ALLOWED folders... KNOWN folders... ROOT dir FILES f...)
#     The rule itself, without targets (also runs in script mode: tools/cmake/check_layers.cmake).
#     Returns the violations, one per entry, in MVFLOW_LAYER_VIOLATIONS (parent scope).

set(MVFLOW_LAYERS_DIR ${CMAKE_CURRENT_LIST_DIR})

# The project's top-level folders: an include into one of them that names no layer is refused too
# (e.g. a stale "engine/mesh.h").
set(MVFLOW_LAYER_ROOTS engine stages io)

function(mvflow_check_layer_files)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "TARGET;OWN;ROOT" "ALLOWED;KNOWN;FILES")
  set(violations)
  set(may ${arg_OWN} ${arg_ALLOWED})
  list(REMOVE_DUPLICATES may)
  list(JOIN may " " may_text)
  foreach(file IN LISTS arg_FILES)
    file(STRINGS "${file}" lines REGEX "^[ \t]*#[ \t]*include[ \t]*\"[^\"]+\"")
    file(RELATIVE_PATH shown "${arg_ROOT}" "${file}")
    foreach(line IN LISTS lines)
      string(REGEX REPLACE "^[ \t]*#[ \t]*include[ \t]*\"([^\"]+)\".*$" "\\1" included "${line}")
      get_filename_component(folder "${included}" DIRECTORY)
      if(folder STREQUAL "")
        continue()  # same-folder include without a path: not a layer crossing
      endif()
      string(REGEX REPLACE "/.*$" "" top "${folder}")
      if(folder IN_LIST may)
        continue()
      endif()
      if(folder IN_LIST arg_KNOWN)
        list(APPEND violations
          "${shown} (target ${arg_TARGET}) includes \"${included}\" from layer ${folder}, which ${arg_TARGET} does not link (it may include: ${may_text})")
      elseif(top IN_LIST MVFLOW_LAYER_ROOTS)
        list(APPEND violations
          "${shown} (target ${arg_TARGET}) includes \"${included}\": ${folder} is no layer folder (it may include: ${may_text})")
      endif()
    endforeach()
  endforeach()
  set(MVFLOW_LAYER_VIOLATIONS "${violations}" PARENT_SCOPE)
endfunction()

# Stops with every violation listed (script mode and configure mode).
function(mvflow_report_layer_violations violations)
  if(violations)
    list(LENGTH violations n)
    list(JOIN violations "\n  " text)
    message(FATAL_ERROR "layer check: ${n} violation(s):\n  ${text}\n"
      "(a file may include its own folder and the layer folders its target links; see tools/cmake/MvflowLayers.cmake)")
  endif()
endfunction()

function(mvflow_layer target)
  cmake_parse_arguments(PARSE_ARGV 1 arg "" "" "HEADERS;SOURCES;PUBLIC;PRIVATE")
  add_library(${target} ${arg_SOURCES})
  string(REGEX REPLACE "^mvflow_" "" short ${target})
  add_library(mvflow::${short} ALIAS ${target})
  file(RELATIVE_PATH folder ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR})
  if(arg_HEADERS)
    # PRIVATE: an exported target must install its PUBLIC file sets as they are, and these are
    # not what is installed (the prefixed copies below are).
    target_sources(${target} PRIVATE FILE_SET HEADERS BASE_DIRS ${PROJECT_SOURCE_DIR} FILES ${arg_HEADERS})
    _mvflow_prefixed_headers(${target} ${folder} "${arg_HEADERS}")
  endif()
  target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>)
  target_compile_features(${target} PUBLIC cxx_std_20)  # the headers need it in a host build too
  # The warnings are this build's own: not part of the exported link interface.
  target_link_libraries(${target} PUBLIC ${arg_PUBLIC} PRIVATE $<BUILD_INTERFACE:mvflow_warnings> ${arg_PRIVATE})
  set_target_properties(${target} PROPERTIES MVFLOW_LAYER_FOLDER ${folder} EXPORT_NAME ${short})
  install(TARGETS ${target} EXPORT mvflowTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  set_property(GLOBAL APPEND PROPERTY MVFLOW_LAYERS ${target})
endfunction()

# The headers of layer \p target as installed: copies under <build>/include/mvflow/<folder>/ whose
# includes read "mvflow/engine/...", remade on every build where a header changed (target
# <target>_headers, part of ALL so that `cmake --install` finds them), installed to
# include/mvflow/<folder>/.
function(_mvflow_prefixed_headers target folder headers)
  set(relative)
  set(sources)
  set(outputs)
  foreach(header IN LISTS headers)
    get_filename_component(source "${header}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    file(RELATIVE_PATH rel ${PROJECT_SOURCE_DIR} ${source})
    list(APPEND relative ${rel})
    list(APPEND sources ${source})
    list(APPEND outputs ${PROJECT_BINARY_DIR}/include/mvflow/${rel})
  endforeach()
  add_custom_command(OUTPUT ${outputs}
    COMMAND ${CMAKE_COMMAND} -DSOURCE_ROOT=${PROJECT_SOURCE_DIR} -DOUTPUT_ROOT=${PROJECT_BINARY_DIR}/include
            "-DROOTS=${MVFLOW_LAYER_ROOTS}" "-DFILES=${relative}" -P ${MVFLOW_LAYERS_DIR}/prefix_includes.cmake
    DEPENDS ${sources} ${MVFLOW_LAYERS_DIR}/prefix_includes.cmake
    COMMENT "Prefixing the includes of ${target}'s headers for installing"
    VERBATIM)
  add_custom_target(${target}_headers ALL DEPENDS ${outputs})
  install(FILES ${outputs} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/mvflow/${folder})
endfunction()

# The layer folders \p target may include: those of the layer targets it links, following
# PUBLIC (usage-requirement) links of every linked target; $<LINK_ONLY:...> entries carry none.
function(_mvflow_linked_layer_folders target out)
  set(seen)
  set(folders)
  get_target_property(queue ${target} LINK_LIBRARIES)
  if(NOT queue)
    set(queue)
  endif()
  while(queue)
    list(POP_FRONT queue item)
    if(item MATCHES "^\\$<LINK_ONLY:" OR NOT TARGET "${item}" OR item IN_LIST seen)
      continue()
    endif()
    get_target_property(aliased ${item} ALIASED_TARGET)
    if(aliased)
      set(item ${aliased})
    endif()
    list(APPEND seen ${item})
    get_target_property(imported ${item} IMPORTED)
    if(imported)
      continue()
    endif()
    get_target_property(folder ${item} MVFLOW_LAYER_FOLDER)
    if(folder)
      list(APPEND folders ${folder})
    endif()
    get_target_property(next ${item} INTERFACE_LINK_LIBRARIES)
    if(next)
      list(APPEND queue ${next})
    endif()
  endwhile()
  set(${out} ${folders} PARENT_SCOPE)
endfunction()

# Every file of \p target: its sources and its header set, as absolute paths.
function(_mvflow_target_files target out)
  get_target_property(dir ${target} SOURCE_DIR)
  get_target_property(sources ${target} SOURCES)
  get_target_property(headers ${target} HEADER_SET)
  set(files)
  foreach(f IN LISTS sources headers)
    if(f AND NOT f MATCHES "\\$<")
      get_filename_component(abs "${f}" ABSOLUTE BASE_DIR "${dir}")
      list(APPEND files "${abs}")
    endif()
  endforeach()
  list(REMOVE_DUPLICATES files)
  set(${out} ${files} PARENT_SCOPE)
endfunction()

function(mvflow_layer_clients)
  set_property(GLOBAL APPEND PROPERTY MVFLOW_LAYER_CLIENTS ${ARGN})
endfunction()

function(mvflow_check_layers)
  get_property(layers GLOBAL PROPERTY MVFLOW_LAYERS)
  get_property(clients GLOBAL PROPERTY MVFLOW_LAYER_CLIENTS)
  set(known)
  foreach(layer IN LISTS layers)
    get_target_property(folder ${layer} MVFLOW_LAYER_FOLDER)
    list(APPEND known ${folder})
  endforeach()
  set(manifest "# Written by mvflow_check_layers (tools/cmake/MvflowLayers.cmake) at configure time.\n")
  string(APPEND manifest "set(MVFLOW_LAYER_ROOT \"${PROJECT_SOURCE_DIR}\")\nset(MVFLOW_LAYER_KNOWN \"${known}\")\n")
  set(all_violations)
  set(all_files)
  set(checked)
  foreach(target IN LISTS layers clients)
    get_target_property(own ${target} MVFLOW_LAYER_FOLDER)
    if(NOT own)
      get_target_property(dir ${target} SOURCE_DIR)
      file(RELATIVE_PATH own ${PROJECT_SOURCE_DIR} ${dir})
    endif()
    _mvflow_linked_layer_folders(${target} allowed)
    _mvflow_target_files(${target} files)
    mvflow_check_layer_files(TARGET ${target} OWN ${own} ALLOWED ${allowed} KNOWN ${known}
                             ROOT ${PROJECT_SOURCE_DIR} FILES ${files})
    list(APPEND all_violations ${MVFLOW_LAYER_VIOLATIONS})
    # A layer owns every source and header in its folder: a file left out would escape the check.
    get_target_property(is_layer ${target} MVFLOW_LAYER_FOLDER)
    if(is_layer)
      file(GLOB present ${PROJECT_SOURCE_DIR}/${own}/*.h ${PROJECT_SOURCE_DIR}/${own}/*.cpp
                        ${PROJECT_SOURCE_DIR}/${own}/*.inc)
      foreach(file IN LISTS present)
        if(NOT file IN_LIST files)
          file(RELATIVE_PATH shown ${PROJECT_SOURCE_DIR} ${file})
          list(APPEND all_violations "${shown} is in the folder of ${target} but not in its SOURCES or HEADERS")
        endif()
      endforeach()
    endif()
    list(APPEND all_files ${files})
    list(APPEND checked ${target})
    string(APPEND manifest "list(APPEND MVFLOW_LAYER_TARGETS ${target})\n"
      "set(MVFLOW_LAYER_${target}_OWN \"${own}\")\n"
      "set(MVFLOW_LAYER_${target}_ALLOWED \"${allowed}\")\n"
      "set(MVFLOW_LAYER_${target}_FILES \"${files}\")\n")
  endforeach()
  mvflow_report_layer_violations("${all_violations}")

  # The same check on every build: a file edited since configuring is checked again before any
  # layer compiles.
  set(manifest_file ${PROJECT_BINARY_DIR}/mvflow_layers_manifest.cmake)
  file(WRITE ${manifest_file} "${manifest}")
  set(stamp ${PROJECT_BINARY_DIR}/mvflow_layers.stamp)
  list(REMOVE_DUPLICATES all_files)
  add_custom_command(OUTPUT ${stamp}
    COMMAND ${CMAKE_COMMAND} -DMANIFEST=${manifest_file} -P ${MVFLOW_LAYERS_DIR}/check_layers.cmake
    COMMAND ${CMAKE_COMMAND} -E touch ${stamp}
    DEPENDS ${all_files} ${manifest_file} ${MVFLOW_LAYERS_DIR}/check_layers.cmake ${MVFLOW_LAYERS_DIR}/MvflowLayers.cmake
    COMMENT "Checking includes across layers"
    VERBATIM)
  add_custom_target(mvflow_layer_check DEPENDS ${stamp})
  foreach(target IN LISTS checked)
    add_dependencies(${target} mvflow_layer_check)
  endforeach()
endfunction()
