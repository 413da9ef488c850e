#include "sensors/builtin_profiles.h"
#include "test/system/recording.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <optional>

#include "common/geometry/align.h"
#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"
#include "kestrel/octomap_t.hpp"
#include "kestrel/rgbd_frame_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "mapper/map_compare.h"
#include "mapper/mapper.h"
#include "mapper/octree_io.h"
#include "sensors/depth_image.h"
#include "vo/sensor_profile.h"

namespace kestrel::test {

Recording read_recording(const std::string& path) {
  Recording r;
  transport::LogReader log(path);
  while (auto e = log.next()) {
    const auto& d = e->data;
    if (e->channel == channel::kState) {
      const auto m = transport::decode_message<kestrel::state_t>(d.data(), d.size(), "STATE");
      if (m.status == kestrel::state_t::STATUS_OK)
        r.states[m.utime] = transport::from_message(m.T_world_body, "STATE");
    } else if (e->channel == channel::kSlamGraph) {
      r.graph = transport::decode_message<kestrel::slam_graph_t>(d.data(), d.size(), "SLAM_GRAPH");
    } else if (e->channel == channel::kSlamCorrection) {
      ++r.corrections;
    } else if (e->channel == channel::kMapOctomap) {
      r.last_map_revision = transport::decode_message<kestrel::octomap_t>(d.data(), d.size(), "MAP_OCTOMAP").revision;
    } else if (e->channel == channel::kVoUpdate && !r.T_body_camera) {
      const auto m = transport::decode_message<kestrel::vo_update_t>(d.data(), d.size(), "VO_UPDATE");
      r.T_body_camera = transport::from_message(m.T_body_camera, "VO_UPDATE");
    }
  }
  return r;
}

std::map<int64_t, RgbdFrame> read_frames(const std::string& path, const std::map<int64_t, Eigen::Isometry3d>& utimes) {
  std::map<int64_t, RgbdFrame> frames;
  transport::LogReader log(path);
  while (auto e = log.next()) {
    if (e->channel != channel::kCameraRgbd) continue;
    const auto m = transport::decode_message<kestrel::rgbd_frame_t>(e->data.data(), e->data.size(), "CAMERA_RGBD");
    if (utimes.count(m.utime)) frames.emplace(m.utime, transport::decode_rgbd(m, "CAMERA_RGBD"));
  }
  return frames;
}

void expect_map_agrees_with_truth(const kestrel::slam_graph_t& graph, const Trajectory& true_camera,
                                  const std::string& source_log, const std::string& map_file, double min_agreement) {
  std::map<int64_t, Eigen::Isometry3d> slam_poses, true_poses;  // T_world_camera by keyframe utime
  for (const auto& kf : graph.keyframes) {
    const std::optional<Eigen::Isometry3d> T = true_camera.at(kf.utime, 20'000);
    if (!T) continue;
    slam_poses[kf.utime] = transport::from_message(kf.T_world_camera, "SLAM_GRAPH");
    true_poses[kf.utime] = *T;
  }
  ASSERT_EQ(true_poses.size(), graph.keyframes.size()) << "keyframes without a true pose";
  ASSERT_GE(true_poses.size(), 3u);
  Eigen::Matrix3Xd a(3, static_cast<Eigen::Index>(true_poses.size())), b(3, a.cols());
  Eigen::Index i = 0;
  for (const auto& [utime, T] : true_poses) {
    a.col(i) = T.translation();
    b.col(i++) = slam_poses.at(utime).translation();
  }
  const std::optional<Eigen::Isometry3d> T_slam_true = align_rigid(a, b);
  ASSERT_TRUE(T_slam_true.has_value());

  const std::map<int64_t, RgbdFrame> frames = read_frames(source_log, true_poses);
  ASSERT_EQ(frames.size(), true_poses.size()) << "keyframes whose frame is not in the log";
  mapper::Mapper reference;  // the process's defaults
  for (const auto& [utime, frame] : frames) {
    // The depth image where the camera truly was when it was taken (a Kinect's depth precedes
    // its colour: by its stamps' difference and the profile's extra latency, the VO's timing
    // model), as the mapper places it (slam_keyframe_t.T_camera_depth). Interpolated across
    // the motion capture's gaps too: fr1_xyz has one of 0.11 s where a keyframe's depth falls.
    const vo::DepthOptions timing = vo::with_sensor(sensors::profile_of_sensor(frame.sensor), vo::VoOptions{}).depth;
    const int64_t depth_time =
        utime + std::llround(1e6 * sensors::depth_time_offset_s(timing.timing(), utime, frame.depth_utime != 0 ? frame.depth_utime : utime));
    const std::optional<Eigen::Isometry3d> T = true_camera.at(depth_time, 120'000);
    ASSERT_TRUE(T.has_value()) << "no true pose at the depth's time " << depth_time;
    reference.insert(frame, *T_slam_true * *T);
  }
  const mapper::VoxelMap flown = mapper::read_map_file(map_file);
  const mapper::MapAgreement agree = mapper::compare_maps(flown, reference.map());
  std::cout << "map: " << flown.num_occupied() << " occupied cells, at true poses " << reference.map().num_occupied()
            << "; class agreement " << agree.class_agreement() << " on " << agree.known_both << " cells, "
            << agree.occupied_a_matched << " of the occupied within a cell of the truth's\n";
  EXPECT_GT(flown.num_occupied(), 500u);
  EXPECT_GT(agree.class_agreement(), min_agreement);
  EXPECT_GT(double(agree.occupied_a_matched), min_agreement * double(agree.occupied_a));
  EXPECT_GT(double(agree.occupied_b_matched), min_agreement * double(agree.occupied_b));
}

}  // namespace kestrel::test
