#pragma once
// A tf tree as kestrel reads it, for bag-import (a whole bag) and ros-bridge (live): each child
// frame's transforms in its parent, by time, from tf2_msgs/TFMessage (/tf and /tf_static).
//
// A frame's pose at a time composes, along its chain of parents, each edge's latest transform
// at or before that time, or the edge's first when there is none before (a rigid mount
// published only once the motion has started). A frame has one parent: a transform giving a
// child a second parent belongs to another tree and is ignored (counted). Frame names are
// compared without the leading '/' of tf before tf2.
//
// The ground truth of a motion-capture chain: the pose of the camera frame in the world frame
// at each transform of the chain's busiest edge (the motion capture; the others are mounts).
//
// Invariants: each edge's transforms are sorted by time (equal times in the order added);
// with keep_us > 0 an edge keeps its transforms of the last keep_us before its newest, and the
// one before them (so that every time in that span is answered as with the whole history).

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <tf2_msgs/TFMessage.h>

namespace kestrel::ros1 {

struct TimedPose {
  int64_t utime = 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
};

class TfTree {
 public:
  /// keep_us: the history kept behind each edge's newest transform (0: all; the bridge keeps seconds).
  explicit TfTree(int64_t keep_us = 0) : keep_us_(keep_us) {}

  /// Adds every transform of `message`, or none: `what` names its source in errors (the bag
  /// and the topic: InputError for a transform that is not a rotation and a translation).
  /// Returns the (child, time) of each transform taken.
  std::vector<std::pair<std::string, int64_t>> add(const tf2_msgs::TFMessage& message, const std::string& what);
  /// Adds one transform of `child` in `parent`; false if `child` has another parent already.
  bool add(const std::string& parent, const std::string& child, int64_t utime, const Eigen::Isometry3d& T_parent_child);

  /// `frame` in the root of its tree at `utime`, and the root's name (`frame` itself if it has no parent).
  std::pair<std::string, Eigen::Isometry3d> in_root(const std::string& frame, int64_t utime) const;
  /// The rotation that turns vectors in `from`'s axes into `to`'s, if the tree joins the two frames.
  std::optional<Eigen::Matrix3d> rotation(const std::string& to, const std::string& from, int64_t utime) const;

  /// The children along the chain from `frame` up to `world` (`frame` first), or empty with
  /// `why` saying why not (not joined, or the same frame).
  std::vector<std::string> chain(const std::string& world, const std::string& frame, std::string& why) const;
  /// The pose of the chain's first frame in its last parent at `utime` (chain from chain()).
  Eigen::Isometry3d along(const std::vector<std::string>& chain, int64_t utime) const;
  /// The child of the chain whose edge has taken the most transforms (all of them counted,
  /// also those no longer kept): the motion capture's; the first such. The chain is not empty.
  std::string busiest(const std::vector<std::string>& chain) const;
  /// "world -> ... -> frame" for a chain from chain().
  std::string path(const std::vector<std::string>& chain) const;
  /// The pose of `frame` in `world` at each transform of the chain's busiest edge; `why` says
  /// which chain (`source` names the topic) or why there is none.
  std::vector<TimedPose> poses(const std::string& world, const std::string& frame, const std::string& source,
                               std::string& why) const;
  /// Live: the same, at those of `taken` (add()'s answer: the transforms just added) that are
  /// the busiest edge's so far. Before the chain is whole there is none.
  std::vector<TimedPose> poses_at(const std::vector<std::pair<std::string, int64_t>>& taken, const std::string& world,
                                  const std::string& frame, const std::string& source, std::string& why) const;

  bool empty() const { return edges_.empty(); }
  /// Transforms ignored because they gave a frame a second parent.
  int64_t second_parents() const { return second_parents_; }

 private:
  struct Edge {
    std::string parent;
    std::vector<TimedPose> samples;  // by time
    int64_t transforms_taken = 0;    // all of them, also those no longer kept
  };
  const Eigen::Isometry3d& value_at(const Edge& edge, int64_t utime) const;
  // chain() for poses() and poses_at(), `why` in their words when there is none.
  std::vector<std::string> truth_chain(const std::string& world, const std::string& frame, const std::string& source,
                                       std::string& why) const;

  int64_t keep_us_;
  std::map<std::string, Edge> edges_;  // by child
  int64_t second_parents_ = 0;
};

/// How IMU samples published in `imu_frame` are turned into the colour images' axes (the
/// body's), bag-import's and ros-bridge's one rule: by the tree's mount when it joins the two
/// frames (no lever arm), else as published; `description` is what the summaries say
/// (`source`: the tf topic, or why there is none).
struct ImuAxes {
  std::optional<Eigen::Matrix3d> R_camera_imu;  ///< none: as published
  std::string description;
};
ImuAxes imu_axes(const TfTree& tree, const std::string& imu_frame, const std::string& colour_frame, int64_t utime,
                 const std::string& source);

}  // namespace kestrel::ros1
