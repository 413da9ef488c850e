#include "tools/soak/proc_memory.h"

#include <fstream>
#include <sstream>

namespace kestrel::soak {
namespace {

// "VmRSS:	  123456 kB" -> 123456 (kB); nullopt for another key or a malformed line.
std::optional<double> kilobytes(const std::string& line, const std::string& key) {
  if (line.compare(0, key.size(), key) != 0 || line.size() <= key.size() || line[key.size()] != ':') return std::nullopt;
  std::istringstream in(line.substr(key.size() + 1));
  double value = 0.0;
  std::string unit;
  if (!(in >> value >> unit) || unit != "kB" || value < 0.0) return std::nullopt;
  return value;
}

}  // namespace

std::optional<Memory> parse_status(const std::string& status) {
  std::istringstream in(status);
  std::optional<double> rss, anon;
  for (std::string line; std::getline(in, line);) {
    if (auto v = kilobytes(line, "VmRSS")) rss = v;
    if (auto v = kilobytes(line, "RssAnon")) anon = v;
  }
  if (!rss) return std::nullopt;
  return Memory{*rss * 1024.0 / 1e6, anon.value_or(0.0) * 1024.0 / 1e6};
}

std::optional<Memory> process_memory(pid_t pid) {
  if (pid <= 0) return std::nullopt;
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();
  return parse_status(text.str());
}

}  // namespace kestrel::soak
