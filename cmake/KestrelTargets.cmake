# Small helpers so that every library, process, test and benchmark is declared the same way.

# -pthread defines _REENTRANT, which the system headers test; some targets get it from their
# dependencies (LCM's pkg-config flags), so every target that uses a precompiled header and the
# header itself get it, or GCC would refuse the header for some of them.
set(_KESTREL_PCH_FLAGS -pthread)

# _kestrel_shared_pch(pch_target PIC DEPS ... HEADERS ...): an object library whose only job
# is to build one precompiled header that other targets take with REUSE_FROM. Headers that
# most files of a kind include (Eigen, OpenCV's core, CLI11, the standard library) are then
# parsed once per build instead of once per file: about a second for each library file and
# five for each tool's main. It is built with the flags its users get (-fPIC for the
# libraries, not for the executables), so GCC accepts it for each of them; -Winvalid-pch on
# the users would say otherwise.
function(_kestrel_shared_pch pch)
  if(TARGET ${pch})
    return()
  endif()
  cmake_parse_arguments(ARG "PIC" "" "DEPS;HEADERS" ${ARGN})
  set(anchor ${CMAKE_BINARY_DIR}/${pch}.cpp)
  file(CONFIGURE OUTPUT ${anchor} CONTENT "// anchors a shared precompiled header\n")
  add_library(${pch} OBJECT ${anchor})
  target_link_libraries(${pch} PRIVATE ${ARG_DEPS} kestrel_options)
  target_compile_options(${pch} PRIVATE ${_KESTREL_PCH_FLAGS})
  set_target_properties(${pch} PROPERTIES POSITION_INDEPENDENT_CODE ${ARG_PIC})
  target_precompile_headers(${pch} PRIVATE ${ARG_HEADERS})
endfunction()

# _kestrel_use_pch(target pch): `target` compiles with `pch` force-included. It links what the
# header needs, so that the header also compiles (slowly) if GCC ever refused the binary one.
function(_kestrel_use_pch target pch deps)
  target_link_libraries(${target} PRIVATE ${deps})
  target_precompile_headers(${target} REUSE_FROM ${pch})
  target_compile_options(${target} PRIVATE ${_KESTREL_PCH_FLAGS} -Winvalid-pch)
endfunction()

set(_KESTREL_STD_HEADERS <algorithm> <cmath> <cstdint> <functional> <limits> <memory> <optional>
    <stdexcept> <string> <utility> <vector>)
set(_KESTREL_LIBRARY_PCH_DEPS Eigen3::Eigen opencv_core)
set(_KESTREL_TOOL_PCH_DEPS Eigen3::Eigen opencv_core CLI11::CLI11 spdlog::spdlog)

# kestrel_library(name [ALGORITHM] SOURCES ... [DEPS ...]) — a component library; headers are
# included from the repository root ("vo/feature_detector.h"). ALGORITHM marks a library that
# knows nothing of LCM, files or clocks: the layering test (test/common/layering_test.cpp)
# fails on any include of it into LCM, tools/, drivers/ or common/transport/, and on any
# library's include of a component it does not link.
function(kestrel_library name)
  cmake_parse_arguments(ARG "ALGORITHM" "" "SOURCES;DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  set_property(GLOBAL APPEND PROPERTY KESTREL_LIBRARIES ${name})
  set_target_properties(${name} PROPERTIES KESTREL_ALGORITHM ${ARG_ALGORITHM})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE kestrel_options)
  set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  _kestrel_shared_pch(kestrel_library_pch PIC DEPS ${_KESTREL_LIBRARY_PCH_DEPS}
    HEADERS <Eigen/Core> <Eigen/Geometry> <opencv2/core.hpp> ${_KESTREL_STD_HEADERS})
  _kestrel_use_pch(${name} kestrel_library_pch "${_KESTREL_LIBRARY_PCH_DEPS}")
endfunction()

# kestrel_tool(name SOURCES ... [DEPS ...]) — an executable `kestrel-<name>`, run as
# `./kestrel <name>`.
function(kestrel_tool name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(kestrel-${name} ${ARG_SOURCES})
  target_link_libraries(kestrel-${name} PRIVATE ${ARG_DEPS} kestrel_options)
  _kestrel_shared_pch(kestrel_tool_pch DEPS ${_KESTREL_TOOL_PCH_DEPS}
    HEADERS <CLI/CLI.hpp> <spdlog/spdlog.h> <Eigen/Core> <Eigen/Geometry> <opencv2/core.hpp>
            <chrono> <filesystem> <fstream> <iostream> ${_KESTREL_STD_HEADERS})
  _kestrel_use_pch(kestrel-${name} kestrel_tool_pch "${_KESTREL_TOOL_PCH_DEPS}")
  set_property(GLOBAL APPEND PROPERTY KESTREL_TOOLS kestrel-${name})
endfunction()

# kestrel_write_layering_manifest(FILE): what the layering test checks, as JSON — every
# library's folder, sources, the kestrel libraries it links and whether it is an ALGORITHM
# library, and every tool's sources (so that a header beside a main belongs to the tool).
# Called once, after every folder is added.
function(kestrel_write_layering_manifest file)
  get_property(libraries GLOBAL PROPERTY KESTREL_LIBRARIES)
  get_property(tools GLOBAL PROPERTY KESTREL_TOOLS)
  set(entries "")
  foreach(target IN LISTS libraries tools)
    get_target_property(dir ${target} SOURCE_DIR)
    file(RELATIVE_PATH dir ${PROJECT_SOURCE_DIR} ${dir})
    get_target_property(sources ${target} SOURCES)
    set(source_list "")
    foreach(source IN LISTS sources)
      cmake_path(ABSOLUTE_PATH source BASE_DIRECTORY ${PROJECT_SOURCE_DIR}/${dir} NORMALIZE)
      cmake_path(IS_PREFIX PROJECT_SOURCE_DIR "${source}" NORMALIZE in_tree)
      if(in_tree)  # generated sources (the sim's built-in worlds) are not checked
        file(RELATIVE_PATH source ${PROJECT_SOURCE_DIR} ${source})
        list(APPEND source_list "\"${source}\"")
      endif()
    endforeach()
    get_target_property(links ${target} LINK_LIBRARIES)
    set(link_list "")
    foreach(link IN LISTS links)
      string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" link "${link}")
      if(link MATCHES "^kestrel_")
        list(APPEND link_list "\"${link}\"")
      endif()
    endforeach()
    list(JOIN source_list ", " source_json)
    list(JOIN link_list ", " link_json)
    set(kind library)
    if(target IN_LIST tools)
      set(kind tool)
    endif()
    get_target_property(algorithm ${target} KESTREL_ALGORITHM)
    if(algorithm)
      set(algorithm true)
    else()
      set(algorithm false)
    endif()
    list(APPEND entries "  {\"name\": \"${target}\", \"kind\": \"${kind}\", \"dir\": \"${dir}\", \"algorithm\": ${algorithm},\n   \"sources\": [${source_json}],\n   \"links\": [${link_json}]}")
  endforeach()
  list(JOIN entries ",\n" body)
  file(WRITE ${file} "[\n${body}\n]\n")
endfunction()

function(_kestrel_test_definitions target)
  target_compile_definitions(${target} PRIVATE
    KESTREL_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    KESTREL_BINARY_DIR="${CMAKE_BINARY_DIR}"
    KESTREL_SHARED_DATA="${KESTREL_SHARED_DATA}")
endfunction()

# The tests' precompiled header: GoogleTest, Eigen and OpenCV's core are most of a small test
# file's compile time.
set(_KESTREL_TEST_PCH_DEPS GTest::gtest GTest::gmock Eigen3::Eigen opencv_core)
function(_kestrel_test_pch)
  if(TARGET kestrel_test_pch)
    return()
  endif()
  _kestrel_shared_pch(kestrel_test_pch DEPS ${_KESTREL_TEST_PCH_DEPS}
    HEADERS <gtest/gtest.h> <gmock/gmock.h> <Eigen/Core> <Eigen/Geometry> <opencv2/core.hpp>
            <filesystem> <fstream> <map> <random> <sstream> ${_KESTREL_STD_HEADERS})
  _kestrel_test_definitions(kestrel_test_pch)
endfunction()

# kestrel_test(name SOURCES ... [DEPS ...] LABELS unit|integration|data [TIMEOUT s])
# A GoogleTest executable registered with ctest. Label `unit`: fast, in-process, no files
# outside the repository. `integration`: several processes or tools, in a private network
# namespace. `data`: needs ../shared/data and skips with a message without it.
function(kestrel_test name)
  cmake_parse_arguments(ARG "" "TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main GTest::gmock
                        kestrel_options)
  _kestrel_test_definitions(${name})
  _kestrel_test_pch()
  _kestrel_use_pch(${name} kestrel_test_pch "${_KESTREL_TEST_PCH_DEPS}")
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/test)
  gtest_discover_tests(${name}
    PROPERTIES LABELS "${ARG_LABELS}" TIMEOUT ${ARG_TIMEOUT}
    DISCOVERY_TIMEOUT 60)
  set_property(GLOBAL APPEND PROPERTY KESTREL_TESTS_${ARG_LABELS} ${name})
endfunction()

# kestrel_benchmark(name SOURCES ... [DEPS ...]) — a Google Benchmark executable in
# <build>/bench; never registered with ctest. Run with `./kestrel bench`.
function(kestrel_benchmark name)
  if(NOT KESTREL_BUILD_BENCHMARKS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  # Not part of `all`: the test suite never needs them; `./kestrel bench` builds `benchmarks`.
  add_executable(${name} EXCLUDE_FROM_ALL ${ARG_SOURCES})
  if(NOT TARGET benchmarks)
    add_custom_target(benchmarks)
  endif()
  add_dependencies(benchmarks ${name})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} benchmark::benchmark kestrel_options)
  target_compile_definitions(${name} PRIVATE
    KESTREL_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    KESTREL_SHARED_DATA="${KESTREL_SHARED_DATA}")
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/bench)
endfunction()
