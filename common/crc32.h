#pragma once
// CRC-32 (IEEE 802.3, reflected: the value zlib, PNG and gzip compute), for the checksums of
// kestrel's own files (the mapper's journal, the SLAM map). Continues from `crc`, so a record
// can be checked in pieces: crc32(b, nb, crc32(a, na)) == crc32 of a then b.

#include <cstddef>
#include <cstdint>

namespace kestrel {

uint32_t crc32(const uint8_t* data, size_t size, uint32_t crc = 0);

}  // namespace kestrel
