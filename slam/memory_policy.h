#pragma once
// Process-wide allocator setting of the SLAM tools (never called by the library).
//
// The optimiser allocates and frees a few megabytes per solve (CHOLMOD's factor and
// workspaces, the block system). With glibc's defaults those come from fresh pages each time
// (mmap, or heap memory trimmed back to the system), and on the project's virtual machines
// the page faults cost more than the factorisation itself: the 1000-keyframe incremental
// update takes 22 ms that way and 10 ms when freed memory is kept (slam/README.md). The same
// as running with GLIBC_TUNABLES=glibc.malloc.mmap_threshold=268435456:glibc.malloc.trim_threshold=1073741824.

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace kestrel::slam {

/// Keeps freed memory in the process instead of returning it to the system.
inline void keep_freed_memory() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 256 << 20);  // blocks below 256 MiB come from the heap...
  mallopt(M_TRIM_THRESHOLD, 1 << 30);    // ...which is not trimmed back below 1 GiB free
#endif
}

}  // namespace kestrel::slam
