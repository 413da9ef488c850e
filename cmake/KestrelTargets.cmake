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
  target_compile_definitions(${name} PRIVATE
    KESTREL_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
    KESTREL_BINARY_DIR="${CMAKE_BINARY_DIR}"
    KESTREL_SHARED_DATA="${KESTREL_SHARED_DATA}")
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
