# Compiler options every kestrel target gets through the `kestrel_options` interface target.
# Warnings on; no -march=native (binaries must run on any x86-64 or ARM machine: SIMD goes
# through portable code the compiler vectorises, or SSE2 with a scalar fallback).

add_library(kestrel_options INTERFACE)
target_compile_options(kestrel_options INTERFACE
  -Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor -Wcast-align -Woverloaded-virtual
  -Wnull-dereference -Wdouble-promotion -Wformat=2 -Wimplicit-fallthrough)

if(KESTREL_SANITIZE)
  target_compile_options(kestrel_options INTERFACE
    -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
    # -O1 and line tables only: fast enough to run the suite, and about half the compile time
    # of -O2 -g on 2 cores, which keeps CI well under its budget.
    -O1 -g1)
  target_link_options(kestrel_options INTERFACE -fsanitize=address,undefined)
endif()

if(CMAKE_BUILD_TYPE STREQUAL "Release")
  # -O3 lets GCC vectorise the per-pixel loops; keep asserts out of the hot paths.
  target_compile_options(kestrel_options INTERFACE -O3)
endif()
