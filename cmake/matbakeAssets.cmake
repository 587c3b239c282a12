# matbake_add_assets(TARGET MANIFEST [ALL] [OUTPUT_DIR dir] [JOBS n] [OPTIONS args...])
#
# A target that runs `matbake build MANIFEST` when anything it read has changed: the manifest, a
# source texture, a scene, its buffers and images (matbake writes a depfile of every file it read,
# so CMake and Ninja or Make learn them after the first build), or matbake itself. matbake then
# rebuilds only the out-of-date outputs.
#   OUTPUT_DIR  where the outputs go (default: ${CMAKE_CURRENT_BINARY_DIR}/TARGET), instead of the
#               manifest's own `output`, so that the source tree stays clean
#   JOBS        parallel jobs inside matbake (default: all cores)
#   OPTIONS     more arguments for `matbake build` (e.g. --force)
#   ALL         build it with the default target
# MATBAKE_EXECUTABLE is the matbake that runs (set by find_package(matbake); may be overridden).
function(matbake_add_assets target manifest)
  cmake_parse_arguments(PARSE_ARGV 2 arg "ALL" "OUTPUT_DIR;JOBS" "OPTIONS")
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "matbake_add_assets: unknown arguments ${arg_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT MATBAKE_EXECUTABLE)
    message(FATAL_ERROR "matbake_add_assets: MATBAKE_EXECUTABLE is not set (find_package(matbake) sets it)")
  endif()
  get_filename_component(manifest "${manifest}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  set(output_dir "${CMAKE_CURRENT_BINARY_DIR}/${target}")
  if(arg_OUTPUT_DIR)
    get_filename_component(output_dir "${arg_OUTPUT_DIR}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_BINARY_DIR}")
  endif()
  set(jobs)
  if(arg_JOBS)
    set(jobs --jobs ${arg_JOBS})
  endif()
  set(state "${CMAKE_CURRENT_BINARY_DIR}/matbake-${target}")
  set(stamp "${state}/build.stamp")
  add_custom_command(
    OUTPUT "${stamp}"
    COMMAND "${CMAKE_COMMAND}" -E make_directory "${state}"
    COMMAND "${MATBAKE_EXECUTABLE}" build "${manifest}" --output-dir "${output_dir}" --quiet ${jobs}
            --depfile "${state}/build.d" --stamp "${stamp}" ${arg_OPTIONS}
    DEPENDS "${manifest}" "${MATBAKE_EXECUTABLE}"
    DEPFILE "${state}/build.d"
    COMMENT "matbake build ${manifest}"
    VERBATIM)
  set(all)
  if(arg_ALL)
    set(all ALL)
  endif()
  add_custom_target(${target} ${all} DEPENDS "${stamp}")
  set_property(TARGET ${target} PROPERTY MATBAKE_OUTPUT_DIR "${output_dir}")
endfunction()
