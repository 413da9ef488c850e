#include "common/text.h"

#include <charconv>

namespace kestrel {

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

bool is_comment_or_blank(std::string_view line) {
  const size_t first = line.find_first_not_of(" \t\r");
  return first == std::string_view::npos || line[first] == '#';
}

std::optional<double> parse_double(std::string_view token) {
  double v = 0.0;
  const char* end = token.data() + token.size();
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);  // from_chars rejects '+'
  const auto [ptr, ec] = std::from_chars(token.data(), end, v);
  if (ec != std::errc() || ptr != end || token.empty()) return std::nullopt;
  return v;
}

std::optional<long long> parse_int(std::string_view token) {
  long long v = 0;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, v);
  if (ec != std::errc() || ptr != end || token.empty()) return std::nullopt;
  return v;
}

}  // namespace kestrel
