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

# kestrel_library(name [ALGORITHM] SOURCES ... [DEPS ...] [PUBLIC_HEADERS ...]) — a component
# library; headers are included from the repository root ("vo/feature_detector.h"). ALGORITHM
# marks a library that knows nothing of LCM, files or clocks: the layering test
# (test/common/layering_test.cpp) fails on any include of it into LCM, tools/, drivers/ or
# common/transport/, and on any library's include of a component it does not link.
# PUBLIC_HEADERS (relative to the library's folder) are what another component's libraries may
# include; the rest are its internals (the layering test fails on such an include). Without
# it every header of the library is public.
function(kestrel_library name)
  cmake_parse_arguments(ARG "ALGORITHM" "" "SOURCES;DEPS;PUBLIC_HEADERS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  set_property(GLOBAL APPEND PROPERTY KESTREL_LIBRARIES ${name})
  set_target_properties(${name} PROPERTIES KESTREL_ALGORITHM ${ARG_ALGORITHM})
  if(ARG_PUBLIC_HEADERS)
    set_target_properties(${name} PROPERTIES KESTREL_PUBLIC_HEADERS "${ARG_PUBLIC_HEADERS}")
  endif()
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE kestrel_options)
  set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  _kestrel_shared_pch(kestrel_library_pch PIC DEPS ${_KESTREL_LIBRARY_PCH_DEPS}
    HEADERS <Eigen/Core> <Eigen/Geometry> <opencv2/core.hpp> ${_KESTREL_STD_HEADERS})
  _kestrel_use_pch(${name} kestrel_library_pch "${_KESTREL_LIBRARY_PCH_DEPS}")
endfunction()

# kestrel_tool(name SOURCES main.cpp ... [DEPS ...] [DEFINITIONS ...]) — a tool or process
# `kestrel-<name>`, run as `./kestrel <name>`. Every tool is compiled into one multi-call
# executable, `kestrel-tools` (kestrel_add_tools_executable, tools/multicall/), and
# <build>/bin/kestrel-<name> is a symbolic link to it: the tool runs by the name it is called
# with. The first source holds the tool's `int main(int argc, char** argv)`; it is compiled
# inside a namespace of its own, eight tools to a translation unit, so that what every tool
# includes (CLI11, spdlog, LCM, Eigen) is compiled once per eight tools rather than once per
# tool (the tool mains were a quarter of a build's compile time). DEFINITIONS must not clash
# between tools: they are the executable's.
function(kestrel_tool name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;DEFINITIONS" ${ARGN})
  list(POP_FRONT ARG_SOURCES main)
  cmake_path(ABSOLUTE_PATH main BASE_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} NORMALIZE)
  set(extra "")
  foreach(source IN LISTS ARG_SOURCES)
    cmake_path(ABSOLUTE_PATH source BASE_DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR} NORMALIZE)
    list(APPEND extra ${source})
  endforeach()
  set_property(GLOBAL APPEND PROPERTY KESTREL_TOOL_NAMES ${name})
  # The link, remade whenever the executable is (so that its time stamp follows the tool's).
  set(link ${CMAKE_RUNTIME_OUTPUT_DIRECTORY}/kestrel-${name})
  add_custom_command(OUTPUT ${link}
    COMMAND ${CMAKE_COMMAND} -E create_symlink kestrel-tools kestrel-${name}
    COMMAND ${CMAKE_COMMAND} -E touch_nocreate kestrel-${name}
    WORKING_DIRECTORY ${CMAKE_RUNTIME_OUTPUT_DIRECTORY}
    DEPENDS kestrel-tools
    COMMENT "kestrel-${name} -> kestrel-tools")
  add_custom_target(kestrel-${name} ALL DEPENDS ${link})
  set_target_properties(kestrel-${name} PROPERTIES KESTREL_TOOL_SOURCES "${main};${extra}"
    KESTREL_TOOL_MAIN ${main} KESTREL_TOOL_EXTRA "${extra}" KESTREL_TOOL_DEPS "${ARG_DEPS}"
    KESTREL_TOOL_DEFINITIONS "${ARG_DEFINITIONS}")
  set_property(GLOBAL APPEND PROPERTY KESTREL_TOOLS kestrel-${name})
endfunction()

# kestrel_add_tools_executable(): the multi-call executable of every kestrel_tool; called once,
# after every folder is added. Each batch file includes first every header its tools include
# (all are include-guarded, so the tools' own #include lines are then no-ops), then each tool's
# main file inside `namespace kestrel_tool_<name>`, where its `main` is an ordinary function;
# tools/multicall/main.cpp calls the one argv[0] names.
# KESTREL_TOOLS (tool names) and KESTREL_TOOLS_OF_TESTS (a test label: the tools the tests with
# that label depend on, by their add_dependencies), when set, name the only tools compiled in,
# with only the libraries they need: the sanitizer builds run a few of the tools
# (`./kestrel test`) and compile only those. Every kestrel-<name> link is still made; a tool left
# out says so when run. Called after the tests are added, for KESTREL_TOOLS_OF_TESTS.
set(KESTREL_TOOLS_PER_BATCH 8)
set(KESTREL_TOOLS "" CACHE STRING "The tools compiled into kestrel-tools (;-separated names); empty: every tool")
set(KESTREL_TOOLS_OF_TESTS "" CACHE STRING
    "A test label (e.g. sanitized): kestrel-tools holds the tools the tests with it depend on (and KESTREL_TOOLS)")
function(kestrel_add_tools_executable)
  get_property(all_names GLOBAL PROPERTY KESTREL_TOOL_NAMES)
  foreach(name IN LISTS KESTREL_TOOLS)
    if(NOT name IN_LIST all_names)
      message(FATAL_ERROR "KESTREL_TOOLS: there is no tool '${name}' (the tools: ${all_names})")
    endif()
  endforeach()
  set(selected ${KESTREL_TOOLS})
  if(KESTREL_TOOLS_OF_TESTS)
    get_property(tests GLOBAL PROPERTY KESTREL_TESTS_${KESTREL_TOOLS_OF_TESTS})
    if(NOT tests)
      message(FATAL_ERROR "KESTREL_TOOLS_OF_TESTS: no test has the label '${KESTREL_TOOLS_OF_TESTS}'")
    endif()
    foreach(test IN LISTS tests)
      get_target_property(test_deps ${test} MANUALLY_ADDED_DEPENDENCIES)
      foreach(dep IN LISTS test_deps)
        if(dep STREQUAL "kestrel_tools")  # every tool
          list(APPEND selected ${all_names})
        elseif(dep MATCHES "^kestrel-(.+)$" AND CMAKE_MATCH_1 IN_LIST all_names)
          list(APPEND selected ${CMAKE_MATCH_1})
        endif()
      endforeach()
    endforeach()
    if(NOT selected)
      message(FATAL_ERROR "KESTREL_TOOLS_OF_TESTS: the tests labelled '${KESTREL_TOOLS_OF_TESTS}' need no tool")
    endif()
  endif()
  set(subset OFF)
  if(KESTREL_TOOLS OR KESTREL_TOOLS_OF_TESTS)
    set(subset ON)
  endif()
  set(names "")
  set(mains "")
  set(extra "")
  set(deps "")
  set(definitions "")
  foreach(name IN LISTS all_names)
    if(subset AND NOT name IN_LIST selected)
      continue()
    endif()
    list(APPEND names ${name})
    foreach(property MAIN EXTRA DEPS DEFINITIONS)
      get_target_property(value kestrel-${name} KESTREL_TOOL_${property})
      if(value)
        string(TOLOWER ${property} var)
        if(var STREQUAL "main")
          set(var mains)
        endif()
        list(APPEND ${var} ${value})
      endif()
    endforeach()
  endforeach()
  set(dir ${CMAKE_BINARY_DIR}/tools_multicall)
  list(LENGTH names count)
  math(EXPR last "${count} - 1")
  set(batches "")
  set(table "")
  set(batch_includes "")
  set(batch_bodies "")
  foreach(i RANGE ${last})
    list(GET names ${i} name)
    list(GET mains ${i} main)
    string(MAKE_C_IDENTIFIER "${name}" id)
    # The #include lines with the conditionals around them (#if KESTREL_SLAM_OFFLINE ...);
    # the conditionals of the code come along as empty blocks.
    file(STRINGS ${main} includes
      REGEX "^[ \t]*#[ \t]*(include[ \t]*[<\"]|if|ifdef|ifndef|elif|else|endif)")
    # The batch copies these lines: an edited main re-runs CMake, so that a new #include
    # reaches the batch instead of failing inside the tool's namespace.
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${main})
    foreach(line IN LISTS includes)
      string(STRIP "${line}" line)
      string(APPEND batch_includes "${line}\n")
    endforeach()
    string(APPEND batch_bodies "namespace kestrel_tool_${id} {\n#include \"${main}\"\n}  // namespace kestrel_tool_${id}\n")
    string(APPEND table "KESTREL_TOOL(\"${name}\", ${id})\n")
    math(EXPR in_batch "(${i} + 1) % ${KESTREL_TOOLS_PER_BATCH}")
    if(in_batch EQUAL 0 OR i EQUAL last)
      list(LENGTH batches n)
      set(batch ${dir}/batch_${n}.cpp)
      file(CONFIGURE OUTPUT ${batch} CONTENT
        "// generated by kestrel_add_tools_executable (cmake/KestrelTargets.cmake)\n${batch_includes}\n${batch_bodies}" @ONLY)
      list(APPEND batches ${batch})
      set_property(SOURCE ${batch} APPEND PROPERTY OBJECT_DEPENDS ${mains})
      set(batch_includes "")
      set(batch_bodies "")
    endif()
  endforeach()
  file(CONFIGURE OUTPUT ${dir}/tool_table.h CONTENT
    "// generated by kestrel_add_tools_executable: KESTREL_TOOL(name, id) for every tool\n${table}" @ONLY)
  add_executable(kestrel-tools ${PROJECT_SOURCE_DIR}/tools/multicall/main.cpp ${batches} ${extra})
  set_target_properties(kestrel-tools PROPERTIES UNITY_BUILD OFF)
  target_include_directories(kestrel-tools PRIVATE ${dir})
  target_compile_definitions(kestrel-tools PRIVATE ${definitions} $<$<BOOL:${subset}>:KESTREL_TOOLS_SUBSET>)
  list(REMOVE_DUPLICATES deps)
  target_link_libraries(kestrel-tools PRIVATE ${deps} kestrel_options)
  _kestrel_shared_pch(kestrel_tool_pch DEPS ${_KESTREL_TOOL_PCH_DEPS}
    HEADERS <CLI/CLI.hpp> <spdlog/spdlog.h> <Eigen/Core> <Eigen/Geometry> <opencv2/core.hpp>
            <chrono> <filesystem> <fstream> <iostream> ${_KESTREL_STD_HEADERS})
  _kestrel_use_pch(kestrel-tools kestrel_tool_pch "${_KESTREL_TOOL_PCH_DEPS}")
  # The mains mostly parse options and wire callbacks; the work is in the libraries (-O0 in the
  # sanitizer build: KestrelWarnings.cmake).
  set_target_properties(kestrel-tools kestrel_tool_pch PROPERTIES KESTREL_MAIN_CODE ON)
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
    if(target IN_LIST tools)
      get_target_property(sources ${target} KESTREL_TOOL_SOURCES)
    else()
      get_target_property(sources ${target} SOURCES)
    endif()
    set(source_list "")
    foreach(source IN LISTS sources)
      cmake_path(ABSOLUTE_PATH source BASE_DIRECTORY ${PROJECT_SOURCE_DIR}/${dir} NORMALIZE)
      cmake_path(IS_PREFIX PROJECT_SOURCE_DIR "${source}" NORMALIZE in_tree)
      if(in_tree)  # generated sources (the sim's built-in worlds) are not checked
        file(RELATIVE_PATH source ${PROJECT_SOURCE_DIR} ${source})
        list(APPEND source_list "\"${source}\"")
      endif()
    endforeach()
    set(links "")
    if(NOT target IN_LIST tools)
      get_target_property(links ${target} LINK_LIBRARIES)
    endif()
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
    set(public_json "null")
    if(NOT target IN_LIST tools)
      get_target_property(public ${target} KESTREL_PUBLIC_HEADERS)
      if(public)
        set(public_list "")
        foreach(header IN LISTS public)
          list(APPEND public_list "\"${dir}/${header}\"")
        endforeach()
        list(JOIN public_list ", " public_json)
        set(public_json "[${public_json}]")
      endif()
    endif()
    list(APPEND entries "  {\"name\": \"${target}\", \"kind\": \"${kind}\", \"dir\": \"${dir}\", \"algorithm\": ${algorithm},\n   \"sources\": [${source_json}],\n   \"links\": [${link_json}],\n   \"public\": ${public_json}}")
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
# _kestrel_test_pch(pch optimized): the header for the tests compiled at -O0 in the sanitizer
# build, or for those that stay at -O1 (OPTIMIZED; KestrelWarnings.cmake): a precompiled
# header is only used at the -O level it was made with.
function(_kestrel_test_pch pch optimized)
  if(TARGET ${pch})
    return()
  endif()
  _kestrel_shared_pch(${pch} DEPS ${_KESTREL_TEST_PCH_DEPS}
    HEADERS <gtest/gtest.h> <gmock/gmock.h> <Eigen/Core> <Eigen/Geometry> <opencv2/core.hpp>
            <filesystem> <fstream> <map> <random> <sstream> ${_KESTREL_STD_HEADERS})
  _kestrel_test_definitions(${pch})
  set_target_properties(${pch} PROPERTIES KESTREL_TEST_CODE ON KESTREL_TEST_OPTIMIZED ${optimized})  # as its users
endfunction()

# kestrel_test(name SOURCES ... [DEPS ...] LABELS unit|integration|data
#              [SANITIZED [SANITIZED_CASES regex]] [THREADS] [OPTIMIZED] [TIMEOUT s])
# A GoogleTest executable registered with ctest. Label `unit`: fast, in-process, no files
# outside the repository. `integration`: several processes or tools, in a private network
# namespace. `data`: needs ../shared/data and skips with a message without it.
# SANITIZED (integration tests): its cases also get the label `sanitized`, and the executable
# joins the target `sanitized_tests`: `./kestrel test` builds those in the sanitizer build
# (build/asan), where test::tool() names the sanitized tools, and runs them there as well as on
# Release. Chosen to run the processes on short inputs: under the sanitizers' -O1 they are 5-20x
# slower (README.md, Tests). SANITIZED_CASES: only the cases ("Suite.Name") the regex matches.
# THREADS: the test exercises code that runs on more than one thread; its cases also get the
# label `threads`, and the executable joins `threads_tests`, which the ThreadSanitizer build
# (build/tsan) builds and runs. OPTIMIZED: the test's own code stays at -O1 in the sanitizer
# build, where the others' is at -O0 (KestrelWarnings.cmake): for a test whose time goes to
# templates it instantiates itself.
function(kestrel_test name)
  cmake_parse_arguments(ARG "SANITIZED;THREADS;OPTIMIZED" "TIMEOUT;SANITIZED_CASES" "SOURCES;DEPS;LABELS" ${ARGN})
  if(NOT ARG_TIMEOUT)
    set(ARG_TIMEOUT 300)
  endif()
  list(LENGTH ARG_LABELS label_count)
  if(NOT label_count EQUAL 1 OR NOT ARG_LABELS MATCHES "^(unit|integration|data)$")
    message(FATAL_ERROR "kestrel_test(${name}): LABELS takes one of unit, integration, data (got '${ARG_LABELS}')")
  endif()
  set(labels ${ARG_LABELS})  # of every case
  if(ARG_THREADS)
    list(APPEND labels threads)
    set_property(GLOBAL APPEND PROPERTY KESTREL_TESTS_threads ${name})
  endif()
  set(sanitized_labels "")  # of the cases that run sanitized
  if(ARG_SANITIZED_CASES AND NOT ARG_SANITIZED)
    message(FATAL_ERROR "kestrel_test(${name}): SANITIZED_CASES goes with SANITIZED")
  endif()
  if(ARG_SANITIZED)
    if(NOT ARG_LABELS STREQUAL "integration")
      message(FATAL_ERROR "kestrel_test(${name}): SANITIZED is for integration tests (the unit tests all run sanitized)")
    endif()
    set(sanitized_labels ${labels} sanitized)
    if(NOT ARG_SANITIZED_CASES)
      set(labels ${sanitized_labels})
      set(ARG_SANITIZED_CASES ".")
    endif()
    set_property(GLOBAL APPEND PROPERTY KESTREL_TESTS_sanitized ${name})
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main GTest::gmock
                        kestrel_options)
  _kestrel_test_definitions(${name})
  # Outside the sanitizer build all test code shares one -O level, and one header serves it.
  if(ARG_OPTIMIZED AND KESTREL_SANITIZE)
    _kestrel_test_pch(kestrel_test_pch_optimized ON)
    set(pch kestrel_test_pch_optimized)
  else()
    _kestrel_test_pch(kestrel_test_pch OFF)
    set(pch kestrel_test_pch)
  endif()
  _kestrel_use_pch(${name} ${pch} "${_KESTREL_TEST_PCH_DEPS}")
  set_target_properties(${name} PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/test
                                           KESTREL_TEST_CODE ON  # -O1 or -O0 (KestrelWarnings.cmake)
                                           KESTREL_TEST_OPTIMIZED "${ARG_OPTIMIZED}")
  gtest_discover_tests(${name}
    PROPERTIES LABELS ${ARG_LABELS} TIMEOUT ${ARG_TIMEOUT}
    DISCOVERY_TIMEOUT 60)
  if(NOT labels STREQUAL ARG_LABELS OR sanitized_labels)
    # gtest_discover_tests takes one label (it spreads a list over the properties, escaped or
    # not), so the full lists are set by a file ctest reads after the discovered tests, on the
    # list of them that the discovery leaves in ${name}_TESTS.
    set(labels_file ${CMAKE_CURRENT_BINARY_DIR}/${name}_labels.cmake)
    if(sanitized_labels)
      set(content "if(DEFINED ${name}_TESTS)
  foreach(kestrel_case IN LISTS ${name}_TESTS)
    if(kestrel_case MATCHES [=[${ARG_SANITIZED_CASES}]=])
      set_tests_properties(\${kestrel_case} PROPERTIES LABELS \"${sanitized_labels}\")
    else()
      set_tests_properties(\${kestrel_case} PROPERTIES LABELS \"${labels}\")
    endif()
  endforeach()
endif()
")
    else()
      set(content "if(DEFINED ${name}_TESTS)\n  set_tests_properties(\${${name}_TESTS} PROPERTIES LABELS \"${labels}\")\nendif()\n")
    endif()
    file(CONFIGURE OUTPUT ${labels_file} CONTENT "${content}" @ONLY)
    set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${labels_file})
  endif()
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
