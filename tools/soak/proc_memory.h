#pragma once
// A running process's memory as the kernel counts it (/proc/PID/status): the resident set
// (VmRSS) and its anonymous part (RssAnon: heap and stacks, not the mapped executable and
// libraries), which is where memory that grows without bound shows.

#include <sys/types.h>

#include <optional>
#include <string>

namespace kestrel::soak {

struct Memory {
  double rss_mb = 0.0;   ///< VmRSS, 10^6 bytes
  double anon_mb = 0.0;  ///< RssAnon, 10^6 bytes (0 on a kernel without it)
};

/// The memory of /proc/PID/status's text; nullopt without a VmRSS line (a zombie has none).
std::optional<Memory> parse_status(const std::string& status);

/// The memory of a running process; nullopt when it has ended (or there is no /proc).
std::optional<Memory> process_memory(pid_t pid);

}  // namespace kestrel::soak
