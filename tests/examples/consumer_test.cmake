# Installs iclap from BUILD_DIR into a fresh prefix, then configures, builds
# and runs SOURCE_DIR/examples/consumer against it, as a user would.
file(REMOVE_RECURSE ${WORK_DIR})
set(_prefix ${WORK_DIR}/prefix)
include(${CMAKE_CURRENT_LIST_DIR}/../cmake/script_util.cmake)
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${_prefix})
if(NOT EXISTS ${_prefix}/share/cmake/iclap/iclap-config.cmake)
  message(FATAL_ERROR "iclap-config.cmake was not installed")
endif()
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/consumer -B ${WORK_DIR}/build
    -DCMAKE_PREFIX_PATH=${_prefix} -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/consumer)
if(NOT out MATCHES "iclap [0-9]+\\.[0-9]+\\.[0-9]+ consumer: ok \\([^\n]*; own point type: same result\\)")
  message(FATAL_ERROR "unexpected consumer output:\n${out}")
endif()
message(STATUS "${out}")
