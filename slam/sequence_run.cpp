#include "slam/sequence_run.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>

#include "common/geometry/se3.h"
#include "slam/backend/odometry_chain.h"
#include "vo/odometry.h"
#include "vo/sensor_profile.h"

namespace kestrel::slam {

SlamRun run_slam_sequence(const std::vector<RgbdFrame>& frames, const sensors::SensorProfile& sensor,
                          const vo::VoOptions& vo_options, const SlamOptions& options,
                          std::shared_ptr<const Vocabulary> vocabulary) {
  return run_slam_sequence(
      frames.size(), [&frames](size_t i) { return frames[i]; }, sensor, vo_options, options, std::move(vocabulary));
}

SlamRun run_slam_sequence(size_t count, const std::function<RgbdFrame(size_t)>& frame_at, const sensors::SensorProfile& sensor,
                          const vo::VoOptions& base_vo_options, const SlamOptions& options,
                          std::shared_ptr<const Vocabulary> vocabulary, std::shared_ptr<const SlamMap> map) {
  const vo::VoOptions vo_options = vo::with_sensor(sensor, base_vo_options);
  vo::VisualOdometry odometry(vo_options);
  OdometryChain chain;
  Slam slam = map ? Slam(std::move(map), options) : Slam(options, std::move(vocabulary));
  SlamRun run;
  // Each reference SLAM's odometry went from (a keyframe, or a frame re-anchored on one), and
  // each frame with the reference it came after.
  struct Reference {
    OdometryReference reference;
    bool continues_previous;  // one odometry segment from the previous reference to this one
  };
  std::vector<Reference> references;
  struct Placed {
    int64_t utime;
    size_t reference;
    Eigen::Isometry3d T_odom_camera;
  };
  std::vector<Placed> placed;
  std::optional<OdometryPose> reference_pose;  // the chain's pose of SLAM's reference
  std::optional<OdometryPose> previous_pose;  // the chain's pose of the previous frame with one
  for (size_t i = 0; i < count; ++i) {
    const RgbdFrame frame = frame_at(i);
    const vo::VoResult& r = run.odometry.emplace_back(odometry.process(frame));
    VoMotion m;
    m.utime = r.utime;
    m.reference_utime = r.reference_utime;
    m.ok = r.status == vo::VoStatus::kOk;
    m.new_reference = r.new_reference;
    m.T_reference_current = r.T_reference_current;
    m.T_body_camera = frame.T_body_camera;
    if (m.ok) {
      m.covariance = r.covariance;
      m.translation_floor_m = r.translation_floor_m;
      m.rotation_floor_rad = r.rotation_floor_rad;
    }
    const std::optional<OdometryPose> pose = chain.add(m);
    if (!pose) continue;
    const OdometryLink link = pose->broken ? OdometryLink::kBroken : OdometryLink::kContinuous;
    // The keyframe's features' timing: the odometry's motion from the previous frame
    // (frame_features.h); none across a restart.
    std::optional<OdometryPose> before = previous_pose;
    previous_pose = *pose;
    if (slam.wants_keyframe(pose->T_odom_camera, link)) {
      sensors::FrameMotion motion;
      if (before && !pose->broken) {
        motion = keyframe_motion(vo_options.depth, frame.utime, frame.depth_utime, before->utime,
                                 before->T_odom_camera.inverse() * pose->T_odom_camera);
      }
      const auto t0 = std::chrono::steady_clock::now();
      std::optional<Matrix6d> odometry_covariance;
      if (link == OdometryLink::kContinuous && reference_pose) {
        odometry_covariance = chain.relative_covariance(*reference_pose, *pose);
      }
      const SlamStep step = slam.add(frame, pose->T_odom_camera, link, odometry_covariance, motion, sensor);
      if (step.new_reference()) {
        reference_pose = *pose;
        references.push_back({slam.reference(), !references.empty() && link == OdometryLink::kContinuous});
      }
      run.keyframe_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      run.candidates_verified += step.candidates;
    }
    run.vo.push_back(frame.utime, pose->T_odom_camera);
    if (!references.empty()) placed.push_back({frame.utime, references.size() - 1, pose->T_odom_camera});
  }
  // Each reference's odometry frame placed by the final graph; a frame moves between its
  // reference's correction and the next's (place_frame).
  std::vector<KeyframeCorrection> corrections;
  for (const Reference& r : references) {
    const Eigen::Isometry3d T_world_reference =
        slam.graph().poses[static_cast<size_t>(r.reference.keyframe_id)] * r.reference.T_keyframe_camera;
    corrections.push_back({r.reference.utime, T_world_reference * r.reference.T_odom_camera.inverse(),
                           r.continues_previous});
  }
  // Frames whose reference stayed provisional (never placed in the saved map) are in no world
  // the map knows: they are left out.
  for (const Placed& p : placed)
    if (slam.in_world(references[p.reference].reference.keyframe_id))
      run.slam.push_back(p.utime, place_frame(corrections, p.reference, p.utime, p.T_odom_camera));
  for (const auto& e : slam.graph().edges) {
    if (e.kind != EdgeKind::kLoopClosure) continue;
    run.loops.push_back({slam.keyframes()[static_cast<size_t>(e.from)].utime,
                         slam.keyframes()[static_cast<size_t>(e.to)].utime, e.measurement});
  }
  run.keyframes = static_cast<int>(slam.keyframes().size());
  run.loop_closures = slam.num_loop_closures();
  run.reanchors = slam.num_reanchors();
  run.coverage_misses = slam.coverage_misses();
  run.inconsistent_loops = slam.num_inconsistent_loops();
  run.relocalisation = slam.relocalisation();
  run.map = slam.map();
  return run;
}

Eigen::Isometry3d place_frame(const std::vector<KeyframeCorrection>& keyframes, size_t newest, int64_t utime,
                              const Eigen::Isometry3d& T_odom_camera) {
  if (newest >= keyframes.size()) throw std::out_of_range("slam: place_frame: no keyframe " + std::to_string(newest));
  const KeyframeCorrection& a = keyframes[newest];
  if (newest + 1 == keyframes.size() || !keyframes[newest + 1].continues_previous) return a.T_world_odom * T_odom_camera;
  const KeyframeCorrection& b = keyframes[newest + 1];
  const double s = static_cast<double>(utime - a.utime) / static_cast<double>(b.utime - a.utime);
  return se3::interpolate(a.T_world_odom, b.T_world_odom, std::clamp(s, 0.0, 1.0)) * T_odom_camera;
}

std::vector<LoopError> loop_errors(const SlamRun& run, const Trajectory& ground_truth) {
  constexpr int64_t kMaxGapUs = 100000;
  std::vector<LoopError> out;
  for (const LoopEdge& edge : run.loops) {
    LoopError e;
    e.edge = edge;
    const auto from = ground_truth.at(edge.from_utime, kMaxGapUs);
    const auto to = ground_truth.at(edge.to_utime, kMaxGapUs);
    if (from && to) {
      const Eigen::Isometry3d E = (from->inverse() * *to).inverse() * edge.T_from_to;
      e.has_truth = true;
      e.translation_m = E.translation().norm();
      e.rotation_rad = Eigen::AngleAxisd(E.linear()).angle();
    }
    out.push_back(e);
  }
  return out;
}

}  // namespace kestrel::slam
