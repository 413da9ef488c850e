#pragma once
// The binary WebSocket messages the page reads (station/web/station.js, readBinary): map
// differences and camera images. Everything else crosses as JSON text (updates.h).
//
// Layout, little-endian (the page reads it with DataView / Float32Array):
//   map:   u8 kind=1, u8 flags (bit 0: reset), u16 0, u32 added, u32 removed, u32 cells after,
//          then (added + removed) x {f32 x, y, z, edge}: the added cells, then the removed.
//   image: u8 kind=2 (colour) or 3 (depth), u8 format (0 JPEG, 1 PNG), u16 0, u32 bytes,
//          then the image file's bytes.
// Both headers are multiples of 4 bytes, so the floats start aligned.

#include <cstdint>
#include <string>
#include <vector>

#include "station/map_cells.h"

namespace kestrel::station {

enum class BinaryKind : uint8_t { kMap = 1, kColour = 2, kDepth = 3 };
enum class ImageFormat : uint8_t { kJpeg = 0, kPng = 1 };

inline constexpr size_t kMapHeaderBytes = 16;
inline constexpr size_t kImageHeaderBytes = 8;
inline constexpr size_t kBytesPerCell = 16;

/// `diff` as a map message; `cells_after` is the page's cell count once applied.
std::string encode_map_diff(const CellDiff& diff, size_t cells_after);
/// The inverse, for tests: throws std::invalid_argument for a message of another kind, a
/// truncated one or one with bytes beyond its cells.
CellDiff decode_map_diff(const std::string& message, size_t* cells_after = nullptr);

std::string encode_image(BinaryKind kind, ImageFormat format, const std::vector<uint8_t>& file_bytes);

}  // namespace kestrel::station
