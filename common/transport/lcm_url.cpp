#include "common/transport/lcm_url.h"

#include <cstdlib>

namespace kestrel::transport {

std::string resolve_lcm_url(const std::string& url) {
  if (!url.empty()) return url;
  if (const char* env = std::getenv("LCM_DEFAULT_URL"); env && *env) return env;
  return kDefaultLcmUrl;
}

}  // namespace kestrel::transport
