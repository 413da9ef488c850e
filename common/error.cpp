#include "common/error.h"

namespace kestrel {

std::string at_line(const std::string& path, int line, const std::string& what) {
  return path + ":" + std::to_string(line) + ": " + what;
}

}  // namespace kestrel
