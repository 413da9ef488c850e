#pragma once
// The LCM URL processes use unless told otherwise.

#include <string>

namespace kestrel::transport {

/// Multicast on the local host only (ttl=0), with a receive buffer large enough for a whole
/// uncompressed 640x480 RGB-D frame (1.5 MB).
inline constexpr const char* kDefaultLcmUrl =
    "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";

/// `url` if not empty, else $LCM_DEFAULT_URL if set, else kDefaultLcmUrl.
std::string resolve_lcm_url(const std::string& url);

}  // namespace kestrel::transport
