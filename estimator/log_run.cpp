#include "estimator/log_run.h"

#include <algorithm>

#include "common/error.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "estimator/messages.h"
#include "estimator/state_estimator.h"
#include "kestrel/ground_truth_t.hpp"

namespace kestrel::estimator {
namespace {

// Decodes and converts one event, or counts it as skipped with its reason.
template <class Msg, class Convert>
bool convert_event(const transport::LogEvent& ev, const Convert& convert, LogSkips& skips) {
  try {
    convert(transport::decode_message<Msg>(ev.data.data(), ev.data.size(), ev.channel));
    return true;
  } catch (const InputError& e) {
    if (skips.rejected++ == 0) skips.first_reason = e.what();
    return false;
  }
}

}  // namespace

LogRunResult run_log(const std::string& path, const EstimatorOptions& options,
                     const LogChannels& channels, double skip_s) {
  transport::LogReader log(path);
  StateEstimator estimator(options);
  LogRunResult r;
  int64_t first_timestamp = -1;
  const auto skip_us = static_cast<int64_t>(skip_s * 1e6);
  auto record = [&](const StepResult& step) {
    if (!step.state) return;
    r.trajectory.push_back(step.state->utime, step.state->nav.T_world_body());
    r.velocity.push_back(step.state->nav.v_world_body);
  };
  while (auto ev = log.next()) {
    if (first_timestamp < 0) first_timestamp = ev->timestamp;
    if (ev->timestamp - first_timestamp < skip_us) continue;
    if (ev->channel == channels.imu) {
      ++r.imu_messages;
      convert_event<kestrel::imu_t>(*ev, [&](const kestrel::imu_t& m) {
        record(estimator.add_imu(imu_from_message(m, ev->channel)));
      }, r.skips);
    } else if (ev->channel == channels.vo) {
      ++r.vo_messages;
      convert_event<kestrel::vo_update_t>(*ev, [&](const kestrel::vo_update_t& m) {
        record(estimator.add_vo(vo_from_message(m, ev->channel)));
      }, r.skips);
    } else if (ev->channel == channels.correction) {
      ++r.correction_messages;
      convert_event<kestrel::slam_correction_t>(*ev, [&](const kestrel::slam_correction_t& m) {
        estimator.add_correction(correction_from_message(m, ev->channel));
      }, r.skips);
    }
  }
  r.skips.damage = log.damage_report();
  if (r.imu_messages == 0 && options.mode == EstimatorMode::kImu)
    throw InputError(path + ": no message on " + channels.imu + ": --mode imu needs the IMU");
  if (r.imu_messages == 0 && r.vo_messages == 0)
    throw InputError(path + ": no message on " + channels.imu + " or " + channels.vo +
                     ": nothing to estimate from");
  r.mode = estimator.mode();
  r.counters = estimator.counters();
  return r;
}

VoAndTruth read_vo_and_truth(const std::string& path, const LogChannels& channels) {
  transport::LogReader log(path);
  VoAndTruth r;
  std::vector<StampedPose> truth;
  bool camera_frame = false;
  while (auto ev = log.next()) {
    if (ev->channel == channels.vo) {
      convert_event<kestrel::vo_update_t>(*ev, [&](const kestrel::vo_update_t& m) {
        r.updates.push_back(vo_from_message(m, ev->channel));
      }, r.skips);
    } else if (ev->channel == channels.ground_truth) {
      convert_event<kestrel::ground_truth_t>(*ev, [&](const kestrel::ground_truth_t& m) {
        const std::string what = ev->channel + " (utime " + std::to_string(m.utime) + ")";
        if (!truth.empty() && m.utime <= truth.back().utime)
          throw InputError(what + ": time stamp not after the previous one");
        const bool camera = m.frame == kestrel::ground_truth_t::FRAME_CAMERA;
        if (!truth.empty() && camera != camera_frame)
          throw InputError(what + ": the ground-truth frame changes along the channel");
        camera_frame = camera;
        truth.push_back({m.utime, transport::from_message(m.T_world_frame, what.c_str())});
      }, r.skips);
    }
  }
  r.skips.damage = log.damage_report();
  const auto first_ok = std::find_if(r.updates.begin(), r.updates.end(),
                                     [](const VoUpdate& u) { return u.ok; });
  if (first_ok == r.updates.end())
    throw InputError(path + ": no successful update on " + channels.vo);
  if (camera_frame) {
    // The VO's own mounting moves a camera ground truth to the body the fit works in.
    const Eigen::Isometry3d T_camera_body = first_ok->T_body_camera.inverse();
    for (StampedPose& p : truth) p.T = p.T * T_camera_body;
  }
  r.truth = Trajectory(std::move(truth));
  return r;
}

}  // namespace kestrel::estimator
