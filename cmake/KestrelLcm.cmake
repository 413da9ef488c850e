# kestrel_lcmtypes(TARGET name FILES a.lcm b.lcm ...)
#
# Debian's LCM 1.3.1 ships no CMake helpers, so this runs lcm-gen itself. It generates the C++
# headers into <build>/lcmtypes/<package>/<type>.hpp at build time and exposes them through an
# INTERFACE library, so that `#include "kestrel/rgbd_frame_t.hpp"` works for anyone linking it.
# The generated decoders are then made to refuse array counts the message cannot hold
# (lcm_guard_counts.cmake): lcm-gen's size arrays from the count before checking it.

find_program(LCM_GEN_EXECUTABLE lcm-gen REQUIRED)

function(kestrel_lcmtypes)
  cmake_parse_arguments(ARG "" "TARGET;PACKAGE" "FILES" ${ARGN})
  set(out_root ${CMAKE_CURRENT_BINARY_DIR}/include)
  set(outputs)
  foreach(lcm_file IN LISTS ARG_FILES)
    get_filename_component(type_name ${lcm_file} NAME_WE)
    list(APPEND outputs ${out_root}/${ARG_PACKAGE}/${type_name}.hpp)
  endforeach()
  list(TRANSFORM ARG_FILES PREPEND ${CMAKE_CURRENT_SOURCE_DIR}/ OUTPUT_VARIABLE abs_files)
  add_custom_command(
    OUTPUT ${outputs}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${out_root}
    COMMAND ${LCM_GEN_EXECUTABLE} --cpp --cpp-std c++11 --cpp-hpath ${out_root} ${abs_files}
    COMMAND ${CMAKE_COMMAND} "-DFILES=${outputs}" -P ${PROJECT_SOURCE_DIR}/cmake/lcm_guard_counts.cmake
    DEPENDS ${abs_files} ${PROJECT_SOURCE_DIR}/cmake/lcm_guard_counts.cmake
    COMMENT "lcm-gen: ${ARG_PACKAGE} message types"
    VERBATIM)
  add_custom_target(${ARG_TARGET}_gen DEPENDS ${outputs})
  add_library(${ARG_TARGET} INTERFACE)
  add_dependencies(${ARG_TARGET} ${ARG_TARGET}_gen)
  target_include_directories(${ARG_TARGET} SYSTEM INTERFACE ${out_root})
  target_link_libraries(${ARG_TARGET} INTERFACE PkgConfig::LCM)
endfunction()
