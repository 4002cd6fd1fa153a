# CTest install_consumer: installs the build into a scratch prefix as README "Installing and using
# mvflow from CMake" says, checks what was installed, then configures, builds and runs the host
# project beside this file against that prefix alone.
#   cmake -DBUILD_DIR=<mvflow build> -DWORK_DIR=<scratch> -DVERSION=<project version>
#         -DGENERATOR=<generator> -DCXX_COMPILER=<c++> [-DLAUNCHER=<ccache>] [-DCXX_FLAGS=<flags>]
#         [-DEXE_LINKER_FLAGS=<flags>] -P install_consumer_test.cmake
cmake_minimum_required(VERSION 3.23)
set(prefix ${WORK_DIR}/prefix)
file(REMOVE_RECURSE ${WORK_DIR})

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()

run("installing" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# The headers are usable with only <prefix>/include on the include path: none includes mvflow
# root-relative, and neither they nor the package name the build or the source tree.
file(GLOB_RECURSE headers ${prefix}/include/mvflow/*)
if(NOT headers)
  message(FATAL_ERROR "no headers under ${prefix}/include/mvflow")
endif()
file(GLOB_RECURSE package_files ${prefix}/lib*/cmake/mvflow/*.cmake)
get_filename_component(source_dir ${CMAKE_CURRENT_LIST_DIR}/../.. REALPATH)
foreach(file IN LISTS headers package_files)
  file(STRINGS ${file} bad REGEX "#[ \t]*include[ \t]*\"(engine|stages|io)/")
  if(bad)
    message(FATAL_ERROR "${file} includes mvflow without the mvflow/ prefix: ${bad}")
  endif()
  file(READ ${file} text)
  foreach(tree ${BUILD_DIR} ${source_dir})
    string(FIND "${text}" "${tree}/" at)
    if(at GREATER -1)
      message(FATAL_ERROR "${file} names ${tree}")
    endif()
  endforeach()
endforeach()

run("mvflow --version" ${prefix}/bin/mvflow --version)
if(NOT output MATCHES "^mvflow ${VERSION}\n")
  message(FATAL_ERROR "the installed mvflow --version says:\n${output}")
endif()
# The installed program uses the installed OpenCV decoder module (found beside it, not in the
# build tree).
file(GLOB module ${prefix}/lib*/mvflow/libmvflow_opencv_decoder.so)
if(NOT module)
  message(FATAL_ERROR "no OpenCV decoder module under ${prefix}/lib*/mvflow")
endif()
get_filename_component(module ${module} REALPATH)
string(FIND "${output}" "other formats by OpenCV (${module})" at)
if(at EQUAL -1)
  message(FATAL_ERROR "the installed mvflow does not use the installed decoder module ${module}:\n${output}")
endif()

set(configure -S ${CMAKE_CURRENT_LIST_DIR} -B ${WORK_DIR}/build -G ${GENERATOR} -DCMAKE_BUILD_TYPE=Release
  -DCMAKE_CXX_COMPILER=${CXX_COMPILER} -DCMAKE_PREFIX_PATH=${prefix} -DMVFLOW_EXPECTED_VERSION=${VERSION})
if(LAUNCHER)
  list(APPEND configure -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
# The build's own flags: a sanitizer build's libraries (tools/sanitize.sh) link only into a
# program built with the same -fsanitize.
if(CXX_FLAGS)
  list(APPEND configure "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}")
endif()
if(EXE_LINKER_FLAGS)
  list(APPEND configure "-DCMAKE_EXE_LINKER_FLAGS=${EXE_LINKER_FLAGS}")
endif()
run("configuring the consumer" ${CMAKE_COMMAND} ${configure})
file(STRINGS ${WORK_DIR}/build/CMakeCache.txt found REGEX "^mvflow_DIR:")
if(NOT found MATCHES "=${prefix}/")
  message(FATAL_ERROR "the consumer found another mvflow: ${found}")
endif()
run("building the consumer" ${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run("running the consumer" ${WORK_DIR}/build/mvflow_consumer ${WORK_DIR})
if(NOT output MATCHES "^mvflow ${VERSION}: [1-9][0-9]* iterations, [1-9][0-9]* vertices read back, closed 1")
  message(FATAL_ERROR "unexpected consumer output:\n${output}")
endif()
message(STATUS "${output}")
