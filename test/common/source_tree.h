#pragma once
// The source tree and the build's layering manifest (<build>/layering.json, written by
// kestrel_write_layering_manifest), as the tree-wide tests read them (layering_test,
// output_files_test).
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

namespace kestrel::test {

/// The text of a file of the source tree, by its path from the root; nothing if unreadable.
inline std::optional<std::string> read_source(const std::string& relative) {
  std::ifstream in(std::filesystem::path(KESTREL_SOURCE_DIR) / relative, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The manifest's targets; nothing if the build did not write it.
inline std::optional<nlohmann::json> read_layering_manifest() {
  std::ifstream in(std::filesystem::path(KESTREL_BINARY_DIR) / "layering.json");
  if (!in) return std::nullopt;
  return nlohmann::json::parse(in);
}

}  // namespace kestrel::test
