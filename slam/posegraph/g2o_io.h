#pragma once
// Reading and writing pose graphs in g2o's text format.
//
//   VERTEX_SE2 id x y theta
//   EDGE_SE2 i j dx dy dtheta I11 I12 I13 I22 I23 I33            (upper triangle of Omega)
//   VERTEX_SE3:QUAT id x y z qx qy qz qw
//   EDGE_SE3:QUAT i j dx dy dz dqx dqy dqz dqw I11 I12 .. I16 I22 .. I66  (21 values)
//   FIX id
//
// Parsing is strict: an unknown tag, a missing or extra field, a non-number, a non-finite
// value, a quaternion far from unit length, a repeated vertex, an edge to a missing vertex, or a file mixing SE(2) and
// SE(3) is an InputError naming the file and line. Blank lines and lines starting with '#'
// are skipped. A file of edges only gets one vertex per id mentioned, posed by chaining the
// odometry edges from the lowest id (pose_graph.h, initialize_by_chaining). Edges whose ends
// differ by one are odometry, the others loop closures. Vertices keep the file's order.
//
// An information matrix that is not positive semi-definite (cubicle.g2o has 1286) would make
// chi2 unbounded below; it is replaced by its nearest positive semi-definite matrix (negative
// eigenvalues set to zero) and counted in G2oStats, so that the caller can say so.

#include <iosfwd>
#include <string>
#include <variant>

#include "slam/posegraph/pose_graph.h"

namespace kestrel::slam {

using AnyPoseGraph = std::variant<PoseGraph2d, PoseGraph3d>;

struct G2oStats {
  int repaired_information = 0;  ///< information matrices projected onto the PSD cone
  int first_repaired_line = 0;
};

/// Reads a g2o file; throws InputError (file:line: what) for a missing or malformed file.
AnyPoseGraph read_g2o(const std::string& path, G2oStats* stats = nullptr);
/// Parses g2o text from `in`; `name` stands for the file in error messages.
AnyPoseGraph parse_g2o(std::istream& in, const std::string& name, G2oStats* stats = nullptr);

/// Writes vertices (in order, with FIX lines for fixed ones), then edges, with the shortest
/// decimal form that reads back to the same double. Throws InputError if it cannot write.
void write_g2o(const std::string& path, const PoseGraph2d& graph);
void write_g2o(const std::string& path, const PoseGraph3d& graph);
void write_g2o(std::ostream& out, const PoseGraph2d& graph);
void write_g2o(std::ostream& out, const PoseGraph3d& graph);

}  // namespace kestrel::slam
