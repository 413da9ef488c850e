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
// value, a coordinate or information entry beyond kMaxG2oMagnitude / kMaxG2oInformation, a
// quaternion far from unit length, a repeated vertex, an edge to a missing vertex, or a file
// mixing SE(2) and SE(3) is an InputError naming the file and line. Blank lines and lines starting with '#'
// are skipped. A file of edges only gets one vertex per id mentioned, posed by chaining the
// odometry edges from the lowest id (pose_graph.h, initialize_by_chaining). Edges whose ends
// differ by one are odometry, the others loop closures. Vertices keep the file's order.
//
// An information matrix that is not positive semi-definite would make chi2 unbounded below, and
// one that is zero makes its edge constrain nothing: both are InputErrors naming the line and
// the edge. Some published files hold non-PSD matrices by the thousand (cubicle.g2o: 5021 of
// 16869); with G2oReadOptions::project_information each is replaced by its nearest positive
// semi-definite matrix (negative eigenvalues set to zero) and counted in G2oStats, so that the
// caller can say so. The bounds keep every chi2 term far from overflow (1e300 gave chi2 NaN).

#include <iosfwd>
#include <string>
#include <variant>

#include "slam/posegraph/pose_graph.h"

namespace kestrel::slam {

using AnyPoseGraph = std::variant<PoseGraph2d, PoseGraph3d>;

/// Largest |coordinate| of a pose or measurement (metres; radians for an SE(2) angle): beyond
/// the size of any map (UTM northings are below 1e7 m), small enough that squared errors
/// times information stay finite.
constexpr double kMaxG2oMagnitude = 1e9;
/// Largest |entry| of an information matrix (a standard deviation of a nanometre).
constexpr double kMaxG2oInformation = 1e18;

struct G2oReadOptions {
  /// Replace information matrices that are not positive semi-definite by the nearest one
  /// (counted in G2oStats) instead of rejecting the file.
  bool project_information = false;
};

struct G2oStats {
  int repaired_information = 0;  ///< information matrices projected onto the PSD cone
  int first_repaired_line = 0;
};

/// Reads a g2o file; throws InputError (file:line: what) for a missing or malformed file.
AnyPoseGraph read_g2o(const std::string& path, G2oStats* stats = nullptr, const G2oReadOptions& options = {});
/// Parses g2o text from `in`; `name` stands for the file in error messages.
AnyPoseGraph parse_g2o(std::istream& in, const std::string& name, G2oStats* stats = nullptr,
                       const G2oReadOptions& options = {});

/// Writes vertices (in order, with FIX lines for fixed ones), then edges, with the shortest
/// decimal form that reads back to the same double. Throws InputError if it cannot write.
void write_g2o(const std::string& path, const PoseGraph2d& graph);
void write_g2o(const std::string& path, const PoseGraph3d& graph);
void write_g2o(std::ostream& out, const PoseGraph2d& graph);
void write_g2o(std::ostream& out, const PoseGraph3d& graph);

}  // namespace kestrel::slam
