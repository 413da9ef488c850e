#pragma once
// Plays a TUM sequence as kestrel messages: CAMERA_RGBD (rgbd_frame_t), IMU (imu_t, the
// accelerometer only) and GROUND_TRUTH (ground_truth_t, FRAME_CAMERA), in the order of
// playback_schedule(), either paced against the wall clock or as fast as possible.
//
// What the messages say:
//  * frames as TumSequence::frame() gives them (body frame = camera optical frame,
//    T_body_camera = identity), encoded with the chosen encodings;
//  * IMU: linear_acceleration in the body (= camera optical) frame, converted from the Kinect
//    accelerometer's axes (drivers/kinect/accelerometer.h) unless raw axes are asked for;
//    fields = HAS_ACCEL; seq counts the samples sent;
//  * GROUND_TRUTH: T_world_frame = groundtruth.txt's pose of the camera, no velocity.
// On each further pass of a loop, every utime and depth_utime is shifted by
// loop_period_us() and frame seqs by the number of RGB images, so both keep increasing.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "common/transport/rgbd_codec.h"
#include "drivers/tum/playback.h"
#include "drivers/tum/tum_sequence.h"

namespace kestrel::tum {

struct PlayerOptions {
  double rate = 1.0;  ///< sensor seconds per wall second; 0 = as fast as possible
  bool loop = false;  ///< start again after the last event (needs rate > 0)
  bool raw_accel_axes = false;  ///< publish the accelerometer's own axes, not the body frame
  transport::RgbdEncoding encoding;
};

/// Where the messages go. `publish` gets the channel, the message utime and its bytes.
struct PlayerSink {
  std::function<void(const std::string& channel, int64_t utime, const std::vector<uint8_t>& bytes)> publish;
  /// Polled between events and while waiting; true ends the playback early.
  std::function<bool()> stopping = [] { return false; };
  /// Called while waiting for an event's time (e.g. Node::spin_once(0) for heartbeats).
  std::function<void()> idle = [] {};
};

struct PlayerStats {
  int64_t frames = 0;
  int64_t imu_samples = 0;
  int64_t ground_truth_poses = 0;
  int64_t passes = 0;           ///< passes started
  double max_lateness_s = 0.0;  ///< worst delay of an event behind its due time (paced only)
  bool stopped = false;         ///< ended by sink.stopping()
};

/// Plays `events` of `sequence`; throws InputError if an image cannot be decoded and
/// std::invalid_argument for unusable options (negative rate, loop without pacing).
PlayerStats play(const TumSequence& sequence, const std::vector<PlaybackEvent>& events,
                 const PlayerOptions& options, const PlayerSink& sink);

}  // namespace kestrel::tum
