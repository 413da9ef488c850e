#include "mapper/octree_stream_check.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "common/error.h"

namespace kestrel::mapper {

namespace {

constexpr int kTreeDepth = 16;  // a node at this depth is a leaf
constexpr int kMaxHeaderLines = 64;

// Offset of the first byte after the header's "data" line.
size_t data_offset(const std::string& s, const std::string& what) {
  size_t pos = 0;
  for (int line = 0; line < kMaxHeaderLines && pos < s.size(); ++line) {
    const size_t end = s.find('\n', pos);
    if (end == std::string::npos) break;
    if (s.compare(pos, end - pos, "data") == 0) return end + 1;
    pos = end + 1;
  }
  throw InputError(what + ": OctoMap header has no 'data' line");
}

[[noreturn]] void corrupt(const std::string& what, const char* why) {
  throw InputError(what + ": corrupt OctoMap tree data (" + why + ")");
}

// Full format: per node a float log-odds and a byte of child flags, children in pre-order.
void check_full(const std::string& s, size_t pos, const std::string& what) {
  std::vector<int> pending{0};  // depths of nodes still to read, next on top
  while (!pending.empty()) {
    const int depth = pending.back();
    pending.pop_back();
    if (s.size() - pos < 5) corrupt(what, "stream ends inside a node");
    float value = 0.0f;
    std::memcpy(&value, s.data() + pos, sizeof value);
    if (!std::isfinite(value)) corrupt(what, "non-finite log-odds");
    const auto children = static_cast<uint8_t>(s[pos + 4]);
    pos += 5;
    if (children != 0 && depth >= kTreeDepth) corrupt(what, "deeper than 16 levels");
    // Pushed in reverse so that child 0 is read first, as OctoMap does.
    for (int i = 7; i >= 0; --i)
      if (children & (1u << i)) pending.push_back(depth + 1);
  }
}

// Binary format: per inner node two bytes of 2-bit child codes (10 free leaf, 01 occupied
// leaf, 11 inner node, 00 none); inner children follow in pre-order.
void check_binary(const std::string& s, size_t pos, const std::string& what) {
  std::vector<int> pending{0};
  while (!pending.empty()) {
    const int depth = pending.back();
    pending.pop_back();
    if (s.size() - pos < 2) corrupt(what, "stream ends inside a node");
    const auto low = static_cast<uint8_t>(s[pos]), high = static_cast<uint8_t>(s[pos + 1]);
    pos += 2;
    const uint16_t codes = static_cast<uint16_t>(low | (high << 8));
    for (int i = 7; i >= 0; --i) {
      if (((codes >> (2 * i)) & 3u) != 3u) continue;
      if (depth + 1 >= kTreeDepth) corrupt(what, "deeper than 16 levels");
      pending.push_back(depth + 1);
    }
  }
}

}  // namespace

void check_octree_stream(const std::string& stream, OctreeFormat format, const std::string& what) {
  const size_t pos = data_offset(stream, what);
  if (pos == stream.size()) return;  // an empty tree writes no node at all
  if (format == OctreeFormat::kFull) {
    check_full(stream, pos, what);
  } else {
    check_binary(stream, pos, what);
  }
}

}  // namespace kestrel::mapper
