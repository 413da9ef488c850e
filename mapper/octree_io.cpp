#include "mapper/octree_io.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>

#include "common/atomic_file.h"
#include "common/error.h"
#include "mapper/octree_stream_check.h"

namespace kestrel::mapper {

std::unique_ptr<octomap::OcTree> to_octree(const VoxelMap& map) {
  auto tree = std::make_unique<octomap::OcTree>(map.resolution());
  const MapOptions& o = map.options();
  tree->setProbHit(o.prob_hit);
  tree->setProbMiss(o.prob_miss);
  tree->setClampingThresMin(o.clamp_min);
  tree->setClampingThresMax(o.clamp_max);
  tree->setOccupancyThres(o.occupancy_threshold);
  map.for_each_cell([&](const Key& k, float v) { tree->setNodeValue(k, v, /*lazy_eval=*/true); });
  tree->updateInnerOccupancy();
  tree->prune();
  return tree;
}

VoxelMap from_octree(const octomap::OcTree& tree, MapOptions options) {
  options.resolution_m = tree.getResolution();
  VoxelMap map(options);
  const unsigned depth = tree.getTreeDepth();
  // A pruned leaf high in the tree stands for a huge cube of cells; refuse trees that would
  // need more than 2^27 cells (a corrupt stream, or a map far beyond any flight).
  constexpr uint64_t kMaxCells = uint64_t{1} << 27;
  uint64_t cells = 0;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const unsigned level = depth - it.getDepth();
    cells += level >= 10 ? kMaxCells + 1 : uint64_t{1} << (3 * level);
    if (cells > kMaxCells) {
      throw InputError("OcTree holds more than " + std::to_string(kMaxCells) +
                       " cells at full resolution");
    }
  }
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const float v = it->getLogOdds();
    const Key base = it.getIndexKey();
    const int n = 1 << (depth - it.getDepth());  // a pruned leaf covers n^3 cells
    for (int z = 0; z < n; ++z) {
      for (int y = 0; y < n; ++y) {
        for (int x = 0; x < n; ++x) {
          map.set(Key(static_cast<uint16_t>(base[0] + x), static_cast<uint16_t>(base[1] + y),
                      static_cast<uint16_t>(base[2] + z)),
                  v);
        }
      }
    }
  }
  return map;
}

namespace {

// The first line of every OctoMap binary (.bt) stream.
constexpr const char* kBinaryHeader = "# Octomap OcTree binary file";

// Debian's liboctomap is built with its debug output on: reading a stream prints "Reading
// binary octree type OcTree" to std::cerr, a line in the planner's log per map it receives.
// Its failures come back as return values, which are turned into errors here. (Its " done."
// after writing goes through stdio's stderr, which cannot be muted without also swallowing
// the process's own log lines: write_binary() below does not call the function that prints it.)
class QuietOctomap {
 public:
  QuietOctomap() : saved_(std::cerr.rdbuf(nullptr)) {}
  ~QuietOctomap() { std::cerr.rdbuf(saved_); }
  QuietOctomap(const QuietOctomap&) = delete;
  QuietOctomap& operator=(const QuietOctomap&) = delete;

 private:
  std::streambuf* saved_;
};

// OcTree::writeBinary() without the " done." Debian's liboctomap prints to stderr after every
// tree (a debug line compiled in; the mapper's log had one per published map): the header its
// readBinary() reads, then the tree's data at maximum likelihood and pruned again, as
// writeBinary() does, so a .bt is canonical: reading it and writing it again gives the same
// bytes. Only the header's optional comment lines differ from writeBinary()'s.
bool write_binary(octomap::OcTree& tree, std::ostream& out) {
  tree.toMaxLikelihood();
  tree.prune();
  out << kBinaryHeader << "\nid " << tree.getTreeType() << "\nsize " << tree.size() << "\nres "
      << tree.getResolution() << "\ndata\n";
  tree.writeBinaryData(out);
  return out.good();
}

void write_stream(const VoxelMap& map, OctreeFormat format, std::ostream& out) {
  const auto tree = to_octree(map);
  const bool ok = format == OctreeFormat::kBinary ? write_binary(*tree, out) : tree->write(out);
  if (!ok) throw std::runtime_error("OctoMap could not write the tree");
}

std::unique_ptr<octomap::OcTree> read_tree(const std::string& bytes, OctreeFormat format, const std::string& what) {
  // Check the first line and the node structure here, so that a wrong file gets our one-line
  // error only, and a corrupt one never reaches OctoMap's unbounded recursion.
  const char* header = format == OctreeFormat::kBinary ? kBinaryHeader : "# Octomap OcTree file";
  if (bytes.compare(0, std::strlen(header), header) != 0) {
    throw InputError(what + ": not an OctoMap " +
                     (format == OctreeFormat::kBinary ? "binary (.bt)" : "full (.ot)") + " stream");
  }
  check_octree_stream(bytes, format, what);
  std::istringstream in(bytes, std::ios::binary);
  std::unique_ptr<octomap::OcTree> tree;
  const QuietOctomap quiet;
  if (format == OctreeFormat::kBinary) {
    tree = std::make_unique<octomap::OcTree>(0.1);
    if (!tree->readBinary(in)) throw InputError(what + ": not a readable OctoMap binary (.bt) tree");
  } else {
    std::unique_ptr<octomap::AbstractOcTree> any(octomap::AbstractOcTree::read(in));
    auto* octree = dynamic_cast<octomap::OcTree*>(any.get());
    if (octree == nullptr) throw InputError(what + ": not a readable OctoMap OcTree (.ot)");
    any.release();
    tree.reset(octree);
  }
  if (!(tree->getResolution() >= 0.005 && tree->getResolution() <= 10.0)) {
    throw InputError(what + ": unusable resolution " + std::to_string(tree->getResolution()));
  }
  return tree;
}

}  // namespace

std::unique_ptr<octomap::OcTree> read_octree(const uint8_t* data, size_t size, OctreeFormat format,
                                             const std::string& what) {
  return read_tree(std::string(reinterpret_cast<const char*>(data), size), format, what);
}

std::vector<uint8_t> encode_octree(const VoxelMap& map, OctreeFormat format) {
  std::ostringstream out(std::ios::binary);
  write_stream(map, format, out);
  const std::string s = out.str();
  return std::vector<uint8_t>(s.begin(), s.end());
}

VoxelMap decode_octree(const uint8_t* data, size_t size, OctreeFormat format, const char* what,
                       MapOptions options) {
  return from_octree(*read_octree(data, size, format, what), options);
}

OctreeFormat format_of(const std::string& path) {
  auto ends_with = [&](const char* ext) {
    const std::string e(ext);
    return path.size() >= e.size() && path.compare(path.size() - e.size(), e.size(), e) == 0;
  };
  if (ends_with(".bt")) return OctreeFormat::kBinary;
  if (ends_with(".ot")) return OctreeFormat::kFull;
  throw InputError(path + ": map files must end in .bt (binary) or .ot (full)");
}

void write_map_file(const VoxelMap& map, const std::string& path) {
  const OctreeFormat format = format_of(path);
  AtomicFile file(path);  // a failed run leaves the previous map, not a cut one
  try {
    write_stream(map, format, file.stream());
  } catch (const std::runtime_error&) {
    if (!file.stream()) throw InputError(path + ": write failed: " + std::strerror(errno));  // a full disk
    throw;
  }
  file.commit();
}

VoxelMap read_map_file(const std::string& path, MapOptions options) {
  const OctreeFormat format = format_of(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open map file");
  std::ostringstream all;
  all << in.rdbuf();
  if (!in) throw InputError(path + ": cannot read map file");
  return from_octree(*read_tree(all.str(), format, path), options);
}

}  // namespace kestrel::mapper
