#include "slam/posegraph/g2o_io.h"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <optional>
#include <vector>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/text.h"

namespace kestrel::slam {
namespace {

enum class Kind { kUnknown, kSe2, kSe3 };

struct RawEdge {
  int64_t from, to;
  int line;
};

class Parser {
 public:
  Parser(std::string name, G2oStats* stats, const G2oReadOptions& options)
      : name_(std::move(name)), stats_(stats), options_(options) {}

  AnyPoseGraph parse(std::istream& in) {
    std::string text;
    while (std::getline(in, text)) {
      ++line_;
      if (is_comment_or_blank(text)) continue;
      fields_ = split_fields(text);
      const std::string_view tag = fields_[0];
      if (tag == "VERTEX_SE2") {
        vertex_se2();
      } else if (tag == "EDGE_SE2") {
        edge_se2();
      } else if (tag == "VERTEX_SE3:QUAT") {
        vertex_se3();
      } else if (tag == "EDGE_SE3:QUAT") {
        edge_se3();
      } else if (tag == "FIX") {
        expect_fields(2);
        fixes_.emplace_back(integer(1), line_);
      } else {
        fail("unknown record '" + std::string(tag) +
             "' (expected VERTEX_SE2, EDGE_SE2, VERTEX_SE3:QUAT, EDGE_SE3:QUAT or FIX)");
      }
    }
    if (in.bad()) throw InputError(name_ + ": read error");
    if (kind_ == Kind::kUnknown) throw InputError(name_ + ": no vertices or edges");
    if (kind_ == Kind::kSe2) return finish(g2_);
    return finish(g3_);
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw InputError(at_line(name_, line_, what)); }

  void expect_fields(size_t n) const {
    if (fields_.size() != n) {
      fail(std::string(fields_[0]) + " needs " + std::to_string(n - 1) + " values, found " +
           std::to_string(fields_.size() - 1));
    }
  }
  // Field k as a finite number of magnitude at most `limit`.
  double number(size_t k, double limit = kMaxG2oMagnitude) const {
    const auto v = parse_double(fields_[k]);
    if (!v) fail("field " + std::to_string(k + 1) + " '" + std::string(fields_[k]) + "' is not a number");
    if (!std::isfinite(*v)) fail("field " + std::to_string(k + 1) + " is not finite");
    if (std::abs(*v) > limit) {
      fail("field " + std::to_string(k + 1) + " " + fmt::format("{:.6g}", *v) + " is beyond " +
           fmt::format("{:g}", limit) + " in magnitude");
    }
    return *v;
  }
  int64_t integer(size_t k) const {
    const auto v = parse_int(fields_[k]);
    if (!v) fail("field " + std::to_string(k + 1) + " '" + std::string(fields_[k]) + "' is not an integer id");
    return *v;
  }
  void set_kind(Kind k) {
    if (kind_ != Kind::kUnknown && kind_ != k) fail("the file mixes SE2 and SE3 records");
    kind_ = k;
  }
  Eigen::Quaterniond quaternion(size_t first) const {  // x y z w in the file
    Eigen::Quaterniond q(number(first + 3), number(first), number(first + 1), number(first + 2));
    const double norm = q.norm();
    if (std::abs(norm - 1.0) > 1e-3) fail("quaternion of norm " + fmt::format("{:.6g}", norm) + " is not a rotation");
    return q.normalized();
  }
  // The edge being read, for messages: "edge 3 -> 7" (the file's ids).
  std::string edge_name() const {
    return "edge " + std::to_string(raw_.back().from) + " -> " + std::to_string(raw_.back().to);
  }
  template <int N>
  Eigen::Matrix<double, N, N> information(size_t first) {
    Eigen::Matrix<double, N, N> I;
    size_t k = first;
    for (int r = 0; r < N; ++r) {
      for (int c = r; c < N; ++c) I(r, c) = I(c, r) = number(k++, kMaxG2oInformation);
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, N, N>> eig(I);
    const double smallest = eig.eigenvalues().minCoeff();
    const double largest = eig.eigenvalues().maxCoeff();
    // Nothing positive: zero, or a matrix whose projection would be zero. The edge would
    // constrain nothing while the file claims a measurement (chi2 0 on any poses).
    if (!(largest > 0.0)) {
      fail(edge_name() + ": information matrix has no positive eigenvalue (largest " +
           fmt::format("{:.6g}", largest) + "): the edge would constrain nothing");
    }
    if (smallest < -1e-9 * std::max(std::abs(largest), 1.0)) {
      if (!options_.project_information) {
        fail(edge_name() + ": information matrix is not positive semi-definite (eigenvalue " +
             fmt::format("{:.6g}", smallest) + ", largest " + fmt::format("{:.6g}", largest) +
             "), so chi2 would be unbounded below (kestrel-posegraph --repair-information projects it)");
      }
      I = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() *
          eig.eigenvectors().transpose();
      I = 0.5 * (I + I.transpose()).eval();
      if (stats_ != nullptr && stats_->repaired_information++ == 0) stats_->first_repaired_line = line_;
    }
    return I;
  }
  void add_vertex_id(int64_t id) {
    if (!vertex_line_.emplace(id, line_).second) {
      fail("vertex " + std::to_string(id) + " already defined on line " + std::to_string(vertex_line_[id]));
    }
  }

  void vertex_se2() {
    set_kind(Kind::kSe2);
    expect_fields(5);
    const int64_t id = integer(1);
    add_vertex_id(id);
    g2_.add_vertex(id, Se2::Pose(number(2), number(3), wrap_angle(number(4))));
  }
  void edge_se2() {
    set_kind(Kind::kSe2);
    expect_fields(12);
    raw_.push_back(RawEdge{integer(1), integer(2), line_});
    if (raw_.back().from == raw_.back().to) fail("edge joins vertex " + std::to_string(raw_.back().from) + " to itself");
    g2_.edges.push_back({0, 0, Se2::Pose(number(3), number(4), wrap_angle(number(5))),
                         information<3>(6), EdgeKind::kOdometry});
  }
  void vertex_se3() {
    set_kind(Kind::kSe3);
    expect_fields(9);
    const int64_t id = integer(1);
    add_vertex_id(id);
    g3_.add_vertex(id, se3_pose(2));
  }
  void edge_se3() {
    set_kind(Kind::kSe3);
    expect_fields(31);
    raw_.push_back(RawEdge{integer(1), integer(2), line_});
    if (raw_.back().from == raw_.back().to) fail("edge joins vertex " + std::to_string(raw_.back().from) + " to itself");
    g3_.edges.push_back({0, 0, se3_pose(3), information<6>(10), EdgeKind::kOdometry});
  }
  Se3::Pose se3_pose(size_t first) const {
    Se3::Pose T = Se3::Pose::Identity();
    T.translation() = Eigen::Vector3d(number(first), number(first + 1), number(first + 2));
    T.linear() = quaternion(first + 3).toRotationMatrix();
    return T;
  }

  // Resolves ids to indices, creating the vertices of an edges-only file.
  template <class Space>
  AnyPoseGraph finish(PoseGraph<Space>& graph) {
    const bool edges_only = graph.poses.empty();
    if (edges_only) {
      std::vector<int64_t> ids;
      for (const auto& r : raw_) {
        ids.push_back(r.from);
        ids.push_back(r.to);
      }
      std::sort(ids.begin(), ids.end());
      ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
      for (const int64_t id : ids) graph.add_vertex(id, Space::identity());
    }
    std::map<int64_t, int> index;
    for (int v = 0; v < graph.num_vertices(); ++v) index[graph.ids[v]] = v;
    for (size_t k = 0; k < raw_.size(); ++k) {
      const auto from = index.find(raw_[k].from), to = index.find(raw_[k].to);
      if (from == index.end() || to == index.end()) {
        line_ = raw_[k].line;
        fail("edge refers to vertex " + std::to_string(from == index.end() ? raw_[k].from : raw_[k].to) +
             ", which the file does not define");
      }
      auto& e = graph.edges[k];
      e.from = from->second;
      e.to = to->second;
      e.kind = std::abs(raw_[k].to - raw_[k].from) == 1 ? EdgeKind::kOdometry : EdgeKind::kLoopClosure;
    }
    for (const auto& [id, line] : fixes_) {
      const auto it = index.find(id);
      if (it == index.end()) {
        line_ = line;
        fail("FIX of vertex " + std::to_string(id) + ", which the file does not define");
      }
      graph.fixed[it->second] = 1;
    }
    if (edges_only) {
      try {
        initialize_by_chaining(graph);
      } catch (const std::invalid_argument& e) {
        // Refused rather than anchored: a file of edges only gives no pose to place it by.
        throw InputError(name_ + ": " + e.what() + " (a file of edges only gives no pose to place it by)");
      }
    }
    return std::move(graph);
  }

  std::string name_;
  G2oStats* stats_;
  G2oReadOptions options_;
  int line_ = 0;
  std::vector<std::string_view> fields_;
  Kind kind_ = Kind::kUnknown;
  PoseGraph2d g2_;
  PoseGraph3d g3_;
  std::vector<RawEdge> raw_;
  std::map<int64_t, int> vertex_line_;
  std::vector<std::pair<int64_t, int>> fixes_;
};

template <int N>
void write_upper(std::ostream& out, const Eigen::Matrix<double, N, N>& I) {
  for (int r = 0; r < N; ++r) {
    for (int c = r; c < N; ++c) fmt::print(out, " {}", I(r, c));
  }
}

void write_fixes(std::ostream& out, const std::vector<int64_t>& ids, const std::vector<char>& fixed) {
  for (size_t v = 0; v < ids.size(); ++v) {
    if (fixed[v]) fmt::print(out, "FIX {}\n", ids[v]);
  }
}

template <class Graph>
void write_file(const std::string& path, const Graph& graph) {
  AtomicFile file(path);  // a failed write leaves no half graph that reads as whole
  write_g2o(file.stream(), graph);
  file.commit();
}

}  // namespace

AnyPoseGraph parse_g2o(std::istream& in, const std::string& name, G2oStats* stats,
                       const G2oReadOptions& options) {
  if (stats != nullptr) *stats = G2oStats{};
  return Parser(name, stats, options).parse(in);
}

AnyPoseGraph read_g2o(const std::string& path, G2oStats* stats, const G2oReadOptions& options) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open");
  return parse_g2o(in, path, stats, options);
}

void write_g2o(std::ostream& out, const PoseGraph2d& graph) {
  for (int v = 0; v < graph.num_vertices(); ++v) {
    const auto& p = graph.poses[v];
    fmt::print(out, "VERTEX_SE2 {} {} {} {}\n", graph.ids[v], p.x(), p.y(), p.z());
  }
  write_fixes(out, graph.ids, graph.fixed);
  for (const auto& e : graph.edges) {
    const auto& z = e.measurement;
    fmt::print(out, "EDGE_SE2 {} {} {} {} {}", graph.ids[e.from], graph.ids[e.to], z.x(), z.y(), z.z());
    write_upper<3>(out, e.information);
    out << '\n';
  }
}

void write_g2o(std::ostream& out, const PoseGraph3d& graph) {
  auto pose = [&out](const Se3::Pose& T) {
    const Eigen::Quaterniond q(T.linear());
    const Eigen::Vector3d t = T.translation();
    fmt::print(out, " {} {} {} {} {} {} {}", t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  };
  for (int v = 0; v < graph.num_vertices(); ++v) {
    fmt::print(out, "VERTEX_SE3:QUAT {}", graph.ids[v]);
    pose(graph.poses[v]);
    out << '\n';
  }
  write_fixes(out, graph.ids, graph.fixed);
  for (const auto& e : graph.edges) {
    fmt::print(out, "EDGE_SE3:QUAT {} {}", graph.ids[e.from], graph.ids[e.to]);
    pose(e.measurement);
    write_upper<6>(out, e.information);
    out << '\n';
  }
}

void write_g2o(const std::string& path, const PoseGraph2d& graph) { write_file(path, graph); }
void write_g2o(const std::string& path, const PoseGraph3d& graph) { write_file(path, graph); }

}  // namespace kestrel::slam
