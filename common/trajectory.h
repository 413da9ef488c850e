#pragma once
// A time-stamped sequence of poses T_world_frame, and its TUM text form
// ("timestamp tx ty tz qx qy qz qw", seconds; note the quaternion order x y z w there).
//
// Invariant: poses are sorted by strictly increasing utime.

#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace kestrel {

struct StampedPose {
  int64_t utime = 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
};

class Trajectory {
 public:
  Trajectory() = default;
  /// Takes poses in any order; throws InputError on a repeated utime.
  explicit Trajectory(std::vector<StampedPose> poses);

  /// Appends a pose; throws std::invalid_argument unless utime is after the last one.
  void push_back(int64_t utime, const Eigen::Isometry3d& T);

  const std::vector<StampedPose>& poses() const { return poses_; }
  size_t size() const { return poses_.size(); }
  bool empty() const { return poses_.empty(); }

  /// The pose at `utime`: the sample itself, or the interpolation between the two samples
  /// around it when both lie within `max_gap_us` of it. Empty otherwise (no sample close
  /// enough on both sides, e.g. inside a gap of the ground truth).
  std::optional<Eigen::Isometry3d> at(int64_t utime, int64_t max_gap_us) const;

 private:
  std::vector<StampedPose> poses_;
};

/// Reads a TUM trajectory file. Lines starting with '#' and blank lines are skipped. Throws
/// InputError naming the file and line for a missing file, a malformed line, a non-finite
/// value, a quaternion far from unit length, or a timestamp not after the previous one.
Trajectory read_tum_trajectory(const std::string& path);

/// Writes `trajectory` in TUM format, atomically (common/atomic_file.h); throws InputError if
/// the file cannot be written.
void write_tum_trajectory(const std::string& path, const Trajectory& trajectory);

}  // namespace kestrel
