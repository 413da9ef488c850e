#include "station/wire.h"

#include <cstring>
#include <stdexcept>

namespace kestrel::station {
namespace {

// The byte order is the page's (little-endian); every target kestrel builds for is too, so a
// memcpy is the conversion. A big-endian host would fail to compile here rather than garble.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the station's wire format is little-endian");

void put_u32(std::string& out, uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }
uint32_t get_u32(const std::string& in, size_t at) {
  uint32_t v;
  std::memcpy(&v, in.data() + at, 4);
  return v;
}
void put_cells(std::string& out, const std::vector<Cell>& cells) {
  for (const Cell& c : cells) {
    const float f[4] = {c.x, c.y, c.z, c.size};
    out.append(reinterpret_cast<const char*>(f), sizeof f);
  }
}

}  // namespace

std::string encode_map_diff(const CellDiff& diff, size_t cells_after) {
  std::string out;
  out.reserve(kMapHeaderBytes + kBytesPerCell * (diff.added.size() + diff.removed.size()));
  out.push_back(static_cast<char>(BinaryKind::kMap));
  out.push_back(static_cast<char>(diff.reset ? 1 : 0));
  out.append(2, '\0');
  put_u32(out, static_cast<uint32_t>(diff.added.size()));
  put_u32(out, static_cast<uint32_t>(diff.removed.size()));
  put_u32(out, static_cast<uint32_t>(cells_after));
  put_cells(out, diff.added);
  put_cells(out, diff.removed);
  return out;
}

CellDiff decode_map_diff(const std::string& m, size_t* cells_after) {
  if (m.size() < kMapHeaderBytes || static_cast<uint8_t>(m[0]) != static_cast<uint8_t>(BinaryKind::kMap))
    throw std::invalid_argument("not a map message");
  CellDiff d;
  d.reset = (static_cast<uint8_t>(m[1]) & 1) != 0;
  const uint64_t added = get_u32(m, 4), removed = get_u32(m, 8);
  if (cells_after) *cells_after = get_u32(m, 12);
  if (m.size() != kMapHeaderBytes + kBytesPerCell * (added + removed))
    throw std::invalid_argument("map message of " + std::to_string(m.size()) + " bytes for " +
                                std::to_string(added + removed) + " cells");
  const auto read = [&](size_t at) {
    float f[4];
    std::memcpy(f, m.data() + at, sizeof f);
    return Cell{f[0], f[1], f[2], f[3]};
  };
  size_t at = kMapHeaderBytes;
  for (uint64_t i = 0; i < added; ++i, at += kBytesPerCell) d.added.push_back(read(at));
  for (uint64_t i = 0; i < removed; ++i, at += kBytesPerCell) d.removed.push_back(read(at));
  return d;
}

std::string encode_image(BinaryKind kind, ImageFormat format, const std::vector<uint8_t>& file_bytes) {
  std::string out;
  out.reserve(kImageHeaderBytes + file_bytes.size());
  out.push_back(static_cast<char>(kind));
  out.push_back(static_cast<char>(format));
  out.append(2, '\0');
  put_u32(out, static_cast<uint32_t>(file_bytes.size()));
  out.append(reinterpret_cast<const char*>(file_bytes.data()), file_bytes.size());
  return out;
}

}  // namespace kestrel::station
