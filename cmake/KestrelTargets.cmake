# Small helpers so that every library, process, test and benchmark is declared the same way.

# kestrel_library(name SOURCES ... [DEPS ...]) — a component library; headers are included
# from the repository root ("vo/feature_detector.h").
function(kestrel_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE kestrel_options)
  set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()

# kestrel_tool(name SOURCES ... [DEPS ...]) — an executable `kestrel-<name>`, run as
# `./kestrel <name>`.
function(kestrel_tool name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(kestrel-${name} ${ARG_SOURCES})
  target_link_libraries(kestrel-${name} PRIVATE ${ARG_DEPS} kestrel_options)
endfunction()

function(_kestrel_test_definitions target)
  target_compile_definitions(${target} PRIVATE
    KESTREL_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    KESTREL_BINARY_DIR="${CMAKE_BINARY_DIR}"
    KESTREL_SHARED_DATA="${KESTREL_SHARED_DATA}")
endfunction()

# -pthread defines _REENTRANT, which the system headers test; some tests get it from their
# dependencies (LCM's pkg-config flags), so every test and the header get it, or GCC would
# refuse the header for some of them.
set(_KESTREL_PCH_FLAGS -pthread)

# One precompiled header for every test: GoogleTest, Eigen and OpenCV's core are parsed once
# per build instead of once per test file (they are most of a small test file's compile
# time). It is built with exactly the flags the tests get, so GCC accepts it for each of them
# (-Winvalid-pch would say otherwise).
function(_kestrel_test_pch)
  if(TARGET kestrel_test_pch)
    return()
  endif()
  set(anchor ${CMAKE_BINARY_DIR}/kestrel_test_pch.cpp)
  file(CONFIGURE OUTPUT ${anchor} CONTENT "// anchors the tests' precompiled header\n")
  add_library(kestrel_test_pch OBJECT ${anchor})
  target_link_libraries(kestrel_test_pch PRIVATE GTest::gtest GTest::gmock Eigen3::Eigen
                        opencv_core kestrel_options)
  target_compile_options(kestrel_test_pch PRIVATE ${_KESTREL_PCH_FLAGS})
  _kestrel_test_definitions(kestrel_test_pch)
  target_precompile_headers(kestrel_test_pch PRIVATE
    <gtest/gtest.h> <gmock/gmock.h> <Eigen/Core> <Eigen/Geometry> <opencv2/core.hpp>
    <algorithm> <cmath> <filesystem> <fstream> <map> <memory> <random> <sstream> <string>
    <vector>)
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
  target_precompile_headers(${name} REUSE_FROM kestrel_test_pch)
  target_compile_options(${name} PRIVATE ${_KESTREL_PCH_FLAGS} -Winvalid-pch)
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
