#include "ros/tf_tree.h"

#include <algorithm>
#include <stdexcept>

#include "common/time.h"
#include "ros/ros_convert.h"

namespace kestrel::ros1 {
namespace {
// Deeper than any real tree; a longer walk is a cycle (a message making a frame its own ancestor).
constexpr size_t kMaxDepth = 64;
}  // namespace

std::vector<std::pair<std::string, int64_t>> TfTree::add(const tf2_msgs::TFMessage& message, const std::string& what) {
  struct Converted {
    std::string parent, child;
    int64_t utime;
    Eigen::Isometry3d T;
  };
  std::vector<Converted> all;  // first: one bad transform and the message changes nothing
  for (const geometry_msgs::TransformStamped& t : message.transforms) {
    Converted c{frame_name(t.header.frame_id), frame_name(t.child_frame_id), to_utime(t.header.stamp), {}};
    c.T = to_isometry(t.transform, what + " at " + format_seconds(c.utime) + " s: " + c.parent + " -> " + c.child);
    all.push_back(std::move(c));
  }
  std::vector<std::pair<std::string, int64_t>> took;
  for (const Converted& c : all)
    if (add(c.parent, c.child, c.utime, c.T)) took.emplace_back(c.child, c.utime);
  return took;
}

bool TfTree::add(const std::string& parent, const std::string& child, int64_t utime,
                 const Eigen::Isometry3d& T_parent_child) {
  auto [it, added] = edges_.try_emplace(child, Edge{parent, {}, 0});
  Edge& edge = it->second;
  if (!added && edge.parent != parent) {
    ++second_parents_;
    return false;
  }
  ++edge.transforms_taken;
  // After the equal times: they keep the order they came in.
  const auto at = std::upper_bound(edge.samples.begin(), edge.samples.end(), utime,
                                   [](int64_t t, const TimedPose& p) { return t < p.utime; });
  edge.samples.insert(at, TimedPose{utime, T_parent_child});
  if (keep_us_ > 0) {
    // Keep the last keep_us before the newest, and the one before them.
    const int64_t from = edge.samples.back().utime - keep_us_;
    auto first_kept = std::lower_bound(edge.samples.begin(), edge.samples.end(), from,
                                       [](const TimedPose& p, int64_t t) { return p.utime < t; });
    if (first_kept != edge.samples.begin()) edge.samples.erase(edge.samples.begin(), std::prev(first_kept));
  }
  return true;
}

const Eigen::Isometry3d& TfTree::value_at(const Edge& edge, int64_t utime) const {
  const auto it = std::upper_bound(edge.samples.begin(), edge.samples.end(), utime,
                                   [](int64_t t, const TimedPose& p) { return t < p.utime; });
  return it == edge.samples.begin() ? it->T : std::prev(it)->T;
}

std::pair<std::string, Eigen::Isometry3d> TfTree::in_root(const std::string& frame, int64_t utime) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  std::string f = frame;
  for (size_t depth = 0; depth < kMaxDepth; ++depth) {
    const auto it = edges_.find(f);
    if (it == edges_.end()) break;
    T = value_at(it->second, utime) * T;
    f = it->second.parent;
  }
  return {f, T};
}

std::optional<Eigen::Matrix3d> TfTree::rotation(const std::string& to, const std::string& from, int64_t utime) const {
  const auto [to_root, T_root_to] = in_root(to, utime);
  const auto [from_root, T_root_from] = in_root(from, utime);
  if (to_root != from_root) return std::nullopt;
  return (T_root_to.inverse() * T_root_from).linear();
}

std::vector<std::string> TfTree::chain(const std::string& world, const std::string& frame, std::string& why) const {
  std::vector<std::string> children;
  for (std::string f = frame; f != world;) {
    const auto it = edges_.find(f);
    if (it == edges_.end() || children.size() > kMaxDepth) {
      why = "no chain of transforms from '" + world + "' to '" + frame + "'";
      return {};
    }
    children.push_back(f);
    f = it->second.parent;
  }
  if (children.empty()) why = "the world and camera frames are the same ('" + world + "')";
  return children;
}

Eigen::Isometry3d TfTree::along(const std::vector<std::string>& chain, int64_t utime) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (const std::string& child : chain) T = value_at(edges_.at(child), utime) * T;
  return T;
}

std::string TfTree::busiest(const std::vector<std::string>& chain) const {
  if (chain.empty()) throw std::invalid_argument("TfTree::busiest: an empty chain");
  return *std::max_element(chain.begin(), chain.end(), [&](const std::string& a, const std::string& b) {
    return edges_.at(a).transforms_taken < edges_.at(b).transforms_taken;
  });
}

std::vector<std::string> TfTree::truth_chain(const std::string& world, const std::string& frame,
                                             const std::string& source, std::string& why) const {
  std::vector<std::string> children = chain(world, frame, why);
  if (children.empty())
    why = "none: " + why + (frame == world ? "" : " on " + source + (edges_.empty() ? " (no transforms)" : ""));
  else
    why = source + ": " + path(children);
  return children;
}

std::vector<TimedPose> TfTree::poses(const std::string& world, const std::string& frame, const std::string& source,
                                     std::string& why) const {
  const std::vector<std::string> children = truth_chain(world, frame, source, why);
  if (children.empty()) return {};
  std::vector<TimedPose> out;
  const Edge& driving = edges_.at(busiest(children));
  out.reserve(driving.samples.size());
  for (const TimedPose& s : driving.samples) {
    if (!out.empty() && out.back().utime == s.utime) continue;
    out.push_back({s.utime, along(children, s.utime)});
  }
  return out;
}

std::vector<TimedPose> TfTree::poses_at(const std::vector<std::pair<std::string, int64_t>>& taken,
                                        const std::string& world, const std::string& frame, const std::string& source,
                                        std::string& why) const {
  const std::vector<std::string> children = truth_chain(world, frame, source, why);
  if (children.empty()) return {};
  const std::string driving = busiest(children);
  std::vector<TimedPose> out;
  for (const auto& [child, utime] : taken)
    if (child == driving && (out.empty() || out.back().utime != utime)) out.push_back({utime, along(children, utime)});
  return out;
}

std::string TfTree::path(const std::vector<std::string>& chain) const {
  std::string p = chain.empty() ? std::string() : chain.front();
  for (const std::string& child : chain) p = edges_.at(child).parent + " -> " + p;
  return p;
}

ImuAxes imu_axes(const TfTree& tree, const std::string& imu_frame, const std::string& colour_frame, int64_t utime,
                 const std::string& source) {
  if (imu_frame.empty() || imu_frame == colour_frame) return {std::nullopt, "as published"};
  if (const auto R = colour_frame.empty() ? std::nullopt : tree.rotation(colour_frame, imu_frame, utime))
    return {R, "rotated from '" + imu_frame + "' to '" + colour_frame + "' by " + source};
  return {std::nullopt, "as published: '" + imu_frame + "' is not joined to the images' '" +
                            (colour_frame.empty() ? std::string("(no colour image yet)") : colour_frame) + "' on " +
                            source};
}

}  // namespace kestrel::ros1
