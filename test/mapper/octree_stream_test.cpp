// Corrupt OctoMap streams are refused before OctoMap reads them: OctoMap's readers recurse
// without a depth limit and past the end of the data, so a stream claiming ever deeper nodes
// would overflow the stack (found by the sanitizer build).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>

#include "common/error.h"
#include "mapper/octree_io.h"
#include "mapper/octree_stream_check.h"

namespace kestrel::mapper {
namespace {

const std::string kFullHeader = "# Octomap OcTree file\nid OcTree\nsize 40\nres 0.1\ndata\n";
const std::string kBinaryHeader = "# Octomap OcTree binary file\nid OcTree\nsize 40\nres 0.1\ndata\n";

std::string full_node(float value, uint8_t children) {
  std::string s(5, '\0');
  std::memcpy(s.data(), &value, 4);
  s[4] = static_cast<char>(children);
  return s;
}

TEST(OctreeStream, RefusesTreesDeeperThanSixteenLevels) {
  // Every node has one child: 40 levels, far past the 16 a tree has.
  std::string full = kFullHeader, binary = kBinaryHeader;
  for (int i = 0; i < 40; ++i) {
    full += full_node(0.5f, 0x01);
    binary += std::string("\x03\x00", 2);  // child 0 is an inner node
  }
  EXPECT_THROW(check_octree_stream(full, OctreeFormat::kFull, "deep.ot"), InputError);
  EXPECT_THROW(check_octree_stream(binary, OctreeFormat::kBinary, "deep.bt"), InputError);
  EXPECT_THROW(decode_octree(reinterpret_cast<const uint8_t*>(full.data()), full.size(), OctreeFormat::kFull, "MAP"),
               InputError);
}

TEST(OctreeStream, RefusesTruncatedDataAndNonFiniteValues) {
  // A root announcing 8 children and then nothing.
  EXPECT_THROW(check_octree_stream(kFullHeader + full_node(0.5f, 0xff), OctreeFormat::kFull, "cut.ot"),
               InputError);
  EXPECT_THROW(check_octree_stream(kBinaryHeader + std::string("\xff\xff", 2), OctreeFormat::kBinary, "cut.bt"),
               InputError);
  EXPECT_THROW(check_octree_stream(kFullHeader + full_node(NAN, 0), OctreeFormat::kFull, "nan.ot"), InputError);
  EXPECT_THROW(check_octree_stream("# Octomap OcTree file\nid OcTree\n", OctreeFormat::kFull, "nodata.ot"),
               InputError);
}

TEST(OctreeStream, AcceptsWhatOctomapWrites) {
  VoxelMap map;
  for (int i = 0; i < 300; ++i) map.update(Key(32768 + i % 11, 32700 + i % 7, 32768 + i % 5), i % 3 ? map.hit() : map.miss());
  for (const OctreeFormat format : {OctreeFormat::kBinary, OctreeFormat::kFull}) {
    const auto bytes = encode_octree(map, format);
    EXPECT_NO_THROW(check_octree_stream(std::string(bytes.begin(), bytes.end()), format, "mine"));
    const auto empty = encode_octree(VoxelMap(), format);
    EXPECT_NO_THROW(check_octree_stream(std::string(empty.begin(), empty.end()), format, "empty"));
  }
}

}  // namespace
}  // namespace kestrel::mapper
