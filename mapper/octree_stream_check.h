#pragma once
// Structural check of an OctoMap stream before OctoMap reads it.
//
// OctoMap's readers (OcTree::readBinary, AbstractOcTree::read) recurse into the node data
// without a depth limit and keep going past the end of the stream, so a corrupt or truncated
// stream can recurse until the stack overflows. This walks the same pre-order layout
// iteratively and accepts the stream only if it is well formed: the header ends in a "data"
// line, every node lies within the bytes given and at most 16 levels deep, and (full format)
// every stored log-odds is finite. An empty data section (an empty tree) is well formed.

#include <string>

#include "mapper/octree_io.h"

namespace kestrel::mapper {

/// Throws InputError naming `what` unless `stream` (header and data) is well formed.
void check_octree_stream(const std::string& stream, OctreeFormat format, const std::string& what);

}  // namespace kestrel::mapper
