#pragma once
// LCM logs with a known motion, written with LogWriter, for the evaluation tests.

#include <filesystem>
#include <vector>

#include "common/geometry/se3.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "test/eval/synthetic.h"

namespace kestrel::eval::test {

using transport::LogWriter;
using transport::to_message;

inline const Eigen::Isometry3d kBodyCamera =
    se3::make(so3::exp(Eigen::Vector3d(-1.2, 1.2, -1.2)), Eigen::Vector3d(0.1, 0.0, -0.05));

inline kestrel::ground_truth_t gt_message(int64_t utime, const Eigen::Isometry3d& T, int8_t frame) {
  kestrel::ground_truth_t m{};
  m.utime = utime;
  m.frame = frame;
  m.T_world_frame = to_message(T);
  return m;
}

inline kestrel::vo_update_t vo_message(int64_t utime, int64_t reference, int8_t status,
                                       const Eigen::Isometry3d& T_reference_current) {
  kestrel::vo_update_t m{};
  m.utime = utime;
  m.reference_utime = reference;
  m.status = status;
  m.T_reference_current = to_message(T_reference_current);
  m.T_body_camera = to_message(kBodyCamera);
  return m;
}

// Ground truth of the camera (or body) on the helix at every frame time (so that it needs no
// interpolation: the answers are exact) and one sample before and after; VO at 30 Hz for 2 s
// measuring each frame against a keyframe taken every 5 frames, exactly; it fails on frame 22.
struct KnownLog {
  static constexpr size_t kFailed = 22;
  std::vector<int64_t> frames = frame_times(60);

  void write(const std::filesystem::path& path, int8_t gt_frame) const {
    LogWriter w(path);
    int64_t keyframe = 0;
    write_gt(w, frames.front() - 10000, gt_frame);
    for (size_t k = 0; k < frames.size(); ++k) {
      write_gt(w, frames[k], gt_frame);
      write_vo(w, k, keyframe);
    }
    write_gt(w, frames.back() + 10000, gt_frame);
    w.close();
  }

  static void write_gt(LogWriter& w, int64_t t, int8_t gt_frame) {
    const Eigen::Isometry3d T_world_camera = helix_pose(t);
    const Eigen::Isometry3d T = gt_frame == kestrel::ground_truth_t::FRAME_BODY
                                    ? T_world_camera * kBodyCamera.inverse()
                                    : T_world_camera;
    w.write_message("GROUND_TRUTH", t, gt_message(t, T, gt_frame));
  }

  void write_vo(LogWriter& w, size_t k, int64_t& keyframe) const {
    using vo = kestrel::vo_update_t;
    const int64_t t = frames[k];
    const Eigen::Isometry3d T_ref_cur = helix_pose(keyframe).inverse() * helix_pose(t);
    const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
    if (k == 0) {
      w.write_message("VO_UPDATE", t, vo_message(t, 0, vo::STATUS_NO_REFERENCE, I));
    } else if (k == kFailed) {
      w.write_message("VO_UPDATE", t, vo_message(t, keyframe, vo::STATUS_INSUFFICIENT_INLIERS, I));
    } else {
      w.write_message("VO_UPDATE", t, vo_message(t, keyframe, vo::STATUS_OK, T_ref_cur));
    }
    if (k % 5 == 0) keyframe = t;  // kFailed is not a multiple of 5
  }
};

}  // namespace kestrel::eval::test
