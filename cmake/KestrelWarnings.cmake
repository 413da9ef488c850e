# Compiler options every kestrel target gets through the `kestrel_options` interface target.
# Warnings on; no -march=native (binaries must run on any x86-64 or ARM machine: SIMD goes
# through portable code the compiler vectorises, or SSE2 with a scalar fallback).

add_library(kestrel_options INTERFACE)
target_compile_options(kestrel_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align -Woverloaded-virtual
  -Wnull-dereference -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough)

# GoogleTest's two-argument TYPED_TEST_SUITE leaves its macro's variadic part empty, which
# clang's -Wpedantic reports on every typed suite (googletest issue 2271); nothing else of ours
# uses variadic macros.
if(CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  target_compile_options(kestrel_options INTERFACE -Wno-gnu-zero-variadic-macro-arguments)
endif()

# No errno from the math functions (never read: errno is only checked after system calls) and
# no floating-point traps (never enabled): sqrt becomes one instruction and the per-pixel loops
# vectorise. Neither changes a result. Project-wide, so that every file of a kind can share
# one precompiled header (KestrelTargets.cmake): GCC refuses a header built with other
# floating-point options.
target_compile_options(kestrel_options INTERFACE -fno-math-errno -fno-trapping-math)

# OctoMap's headers print debug lines to stderr ("Writing N nodes to output stream...") from
# the templates compiled into our own code unless NDEBUG is set; a Debug or sanitizer build
# would then print what a Release build does not. Off in every build.
target_compile_definitions(kestrel_options INTERFACE OCTOMAP_NODEBUGOUT)

if(KESTREL_SANITIZE)
  target_compile_options(kestrel_options INTERFACE
    -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
    # Every UBSan check but four that AddressSanitizer covers where it matters, each a tenth to
    # a fifth of an Eigen-heavy file's compile time: object-size and pointer-overflow (ASan
    # finds the access outside an object that either leads to), null (ASan reports the
    # dereference, with its stack) and vptr (a dynamic type check; kestrel has few class
    # hierarchies and no downcasts). docs/decisions/2026-12-02-compiler-and-sanitizer-cost.md
    # and 2026-12-04-sanitizer-checks.md.
    -fno-sanitize=object-size,pointer-overflow,null,vptr
    # -O1 and line tables only: fast enough to run the suite, and about half the compile time
    # of -O2 -g on 2 cores.
    -O1 -g1)
  target_link_options(kestrel_options INTERFACE
    -fsanitize=address,undefined -fno-sanitize=object-size,pointer-overflow,null,vptr)
  # UBSan's alignment check only where bytes from outside are read: not in the ALGORITHM
  # libraries (which know nothing of files or LCM: their inputs are typed values that the
  # decoders in common/, drivers/, ros/ and station/ made, and those keep the check) nor in the
  # tests' own code. It was 7-21 % of the compile time of their heaviest files, the Eigen-heavy
  # ones, where Eigen's own assertion (on in this build: no NDEBUG) already stops an unaligned
  # fixed-size object. docs/decisions/2026-12-05-ci-time-alignment-check-and-shorter-flights.md.
  target_compile_options(kestrel_options INTERFACE
    "$<$<OR:$<BOOL:$<TARGET_PROPERTY:KESTREL_ALGORITHM>>,$<BOOL:$<TARGET_PROPERTY:KESTREL_TEST_CODE>>>:-fno-sanitize=alignment>")
  if(CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    # No instrumentation for use-after-return, which ASAN_OPTIONS never turns on (clang 14
    # emits it for every function with a stack object all the same): the sanitized unit tests
    # ran in 81 s instead of 125 s.
    target_compile_options(kestrel_options INTERFACE -fsanitize-address-use-after-return=never)
  endif()
endif()

# The ThreadSanitizer build (`./kestrel test --tsan`, build/tsan): the tests of what runs on
# more than one thread, on their own (README.md, Tests). -O1 and line tables as above.
if(KESTREL_TSAN)
  if(KESTREL_SANITIZE)
    message(FATAL_ERROR "KESTREL_TSAN and KESTREL_SANITIZE exclude each other (ThreadSanitizer runs alone)")
  endif()
  target_compile_options(kestrel_options INTERFACE -fsanitize=thread -fno-omit-frame-pointer -O1 -g1)
  target_link_options(kestrel_options INTERFACE -fsanitize=thread)
endif()

# In the ASan/UBSan build the code that only drives the libraries is compiled at -O0: the
# tests' own code (KESTREL_TEST_CODE) and the tools' mains (KESTREL_MAIN_CODE). The libraries
# keep -O1. With the sanitizers' instrumentation, -O1 was 38-63 % of such a file's compile time,
# and the test files are the largest part of that build. A test whose own code does heavy work
# (the mapper's, OctoMap's and Eigen's templates instantiated in the test, images drawn there)
# is marked OPTIMIZED (kestrel_test) and stays at -O1, with a precompiled header of its own.
# Not in the ThreadSanitizer build, whose tests are about timing between threads.
# docs/decisions/2026-12-06-ci-time-test-code-at-O0.md.
if(KESTREL_SANITIZE)
  set(_kestrel_driving_code "$<OR:$<BOOL:$<TARGET_PROPERTY:KESTREL_MAIN_CODE>>,$<AND:$<BOOL:$<TARGET_PROPERTY:KESTREL_TEST_CODE>>,$<NOT:$<BOOL:$<TARGET_PROPERTY:KESTREL_TEST_OPTIMIZED>>>>>")
  target_compile_options(kestrel_options INTERFACE "$<${_kestrel_driving_code}:-O0>")
endif()

# The fuzz build (`./kestrel fuzz`, fuzz/README.md): every library is compiled with libFuzzer's
# coverage instrumentation, on top of the sanitizers, so that the fuzzer sees which branches of
# the decoders an input reached; kestrel-fuzz links libFuzzer's driver (fuzz/CMakeLists.txt).
if(KESTREL_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang" OR NOT KESTREL_SANITIZE)
    message(FATAL_ERROR "KESTREL_FUZZ needs clang and KESTREL_SANITIZE=ON (the fuzz preset)")
  endif()
  target_compile_options(kestrel_options INTERFACE -fsanitize=fuzzer-no-link)
  target_link_options(kestrel_options INTERFACE -fsanitize=fuzzer-no-link)
endif()

if(CMAKE_BUILD_TYPE STREQUAL "Release")
  # -O3 lets GCC vectorise the per-pixel loops; keep asserts out of the hot paths. The tests'
  # own code (targets with KESTREL_TEST_CODE: the test executables and their precompiled
  # header) is compiled at -O1: it drives the libraries, which keep -O3, and -O3 was most of
  # its compile time (docs/decisions/2026-12-02-process-start-and-test-code.md). On x86-64
  # (SSE2, no FMA without -march) the level changes no floating-point result.
  target_compile_options(kestrel_options INTERFACE
    $<IF:$<BOOL:$<TARGET_PROPERTY:KESTREL_TEST_CODE>>,-O1,-O3>)
endif()

# LLVM's linker when the system has it (Debian's `lld`, in ../kestrel's package list): it
# links the 100-odd executables of a build several times faster than GNU ld, which matters most
# for the sanitizer build's large binaries. The output is the same program; without lld the
# default linker is used.
include(CheckLinkerFlag)
check_linker_flag(CXX -fuse-ld=lld KESTREL_HAVE_LLD)
if(KESTREL_HAVE_LLD)
  target_link_options(kestrel_options INTERFACE -fuse-ld=lld)
endif()
