#pragma once
// A trajectory as read for evaluation, with what the evaluation must know about it: which
// frame its poses place in the world, every frame it has a record for (including frames the
// estimator failed on, which have no pose), the camera mounting when known, and what was
// wrong with the input. Readers: TUM files here, LCM logs in tools/eval/log_input.h.

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/trajectory.h"

namespace kestrel::eval {

/// The frame whose pose a trajectory holds. TUM files do not say: kUnspecified.
enum class PoseFrame { kUnspecified, kBody, kCamera };
const char* to_string(PoseFrame frame);

/// What was skipped while reading an LCM channel (all zero for a TUM file).
struct InputDiagnostics {
  size_t messages = 0;           ///< events on the channel
  size_t wrong_type = 0;         ///< of another message type than the channel's
  size_t corrupt = 0;            ///< of the channel's type, but not decodable
  size_t invalid_pose = 0;       ///< non-finite values or a non-unit quaternion
  size_t out_of_order = 0;       ///< utime not after the previous message's
  size_t no_pose = 0;            ///< the producer reported no estimate (status)
  size_t unknown_reference = 0;  ///< VO: reference frame without a pose (chained on)
  std::string damage;            ///< the log's damage report, "" if intact
  /// One line per kind of problem seen, naming the channel; empty if none.
  std::vector<std::string> problems() const;
};

struct TrajectoryInput {
  std::string source;                 ///< "path" or "path:CHANNEL"
  std::string format;                 ///< e.g. "TUM trajectory", "LCM log, vo_update_t"
  Trajectory trajectory;              ///< T_world_<frame>
  std::vector<int64_t> frame_utimes;  ///< every frame with a record, with or without a pose
  PoseFrame frame = PoseFrame::kUnspecified;
  std::optional<Eigen::Isometry3d> T_body_camera;
  InputDiagnostics diagnostics;
};

/// Reads a TUM trajectory file (read_tum_trajectory: InputError naming file:line).
TrajectoryInput read_tum_input(const std::string& path);

/// The time stamps of a TUM list ("timestamp ..." per line, e.g. rgb.txt; a trajectory file
/// works too). Throws InputError naming file:line for a missing or malformed file or a time
/// stamp not after the previous one.
std::vector<int64_t> read_frame_list(const std::string& path);

/// Puts `gt` into the frame of `est` when both frames are known and differ, with the camera
/// mounting of either input (T_world_camera = T_world_body * T_body_camera). Returns one line
/// saying which poses are compared. Throws InputError when a conversion is needed but no
/// T_body_camera is known.
std::string reconcile_frames(TrajectoryInput& gt, const TrajectoryInput& est);

}  // namespace kestrel::eval
