#include "tools/eval/trajectory_input.h"

#include <fstream>

#include "common/error.h"
#include "common/text.h"
#include "common/time.h"

namespace kestrel::eval {
namespace {

void add_problem(std::vector<std::string>& out, size_t count, const std::string& what) {
  if (count > 0) out.push_back(std::to_string(count) + " " + what);
}

Trajectory transformed(const Trajectory& t, const Eigen::Isometry3d& T_from_to) {
  Trajectory out;
  for (const StampedPose& p : t.poses()) out.push_back(p.utime, p.T * T_from_to);
  return out;
}

}  // namespace

const char* to_string(PoseFrame frame) {
  switch (frame) {
    case PoseFrame::kUnspecified:
      return "unspecified";
    case PoseFrame::kBody:
      return "body";
    case PoseFrame::kCamera:
      return "camera";
  }
  return "?";
}

std::vector<std::string> InputDiagnostics::problems() const {
  std::vector<std::string> out;
  if (!damage.empty()) out.push_back(damage);
  add_problem(out, wrong_type, "message(s) of another type skipped");
  add_problem(out, corrupt, "corrupt message(s) skipped");
  add_problem(out, invalid_pose, "message(s) with a non-finite or non-unit pose rejected");
  add_problem(out, out_of_order, "message(s) not after the previous one in time skipped");
  add_problem(out, no_pose, "frame(s) without an estimate (status)");
  add_problem(out, unknown_reference,
              "VO frame(s) whose reference has no pose, chained from the last known pose");
  return out;
}

TrajectoryInput read_tum_input(const std::string& path) {
  TrajectoryInput in;
  in.source = path;
  in.format = "TUM trajectory";
  in.trajectory = read_tum_trajectory(path);
  for (const StampedPose& p : in.trajectory.poses()) in.frame_utimes.push_back(p.utime);
  return in;
}

std::vector<int64_t> read_frame_list(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open frame list");
  std::vector<int64_t> utimes;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (is_comment_or_blank(line)) continue;
    const std::string stamp(split_fields(line).front());
    const auto utime = parse_seconds(stamp);
    if (!utime) throw InputError(at_line(path, line_no, "bad timestamp '" + stamp + "'"));
    if (!utimes.empty() && *utime <= utimes.back())
      throw InputError(
          at_line(path, line_no, "timestamp " + stamp + " is not after the previous one"));
    utimes.push_back(*utime);
  }
  if (in.bad()) throw InputError(path + ": read error");
  return utimes;
}

std::string reconcile_frames(TrajectoryInput& gt, const TrajectoryInput& est) {
  if (gt.frame == PoseFrame::kUnspecified || est.frame == PoseFrame::kUnspecified) {
    return std::string("poses as given (ground truth: ") + to_string(gt.frame) +
           ", estimate: " + to_string(est.frame) + "; a TUM file does not say which frame)";
  }
  if (gt.frame == est.frame) return std::string(to_string(est.frame)) + " poses";
  const auto& T_body_camera = est.T_body_camera ? est.T_body_camera : gt.T_body_camera;
  if (!T_body_camera) {
    throw InputError(gt.source + ": ground truth of the " + to_string(gt.frame) +
                     " but an estimate of the " + to_string(est.frame) +
                     ", and neither input gives T_body_camera (a VO_UPDATE message)");
  }
  const Eigen::Isometry3d T_gt_est =
      gt.frame == PoseFrame::kBody ? *T_body_camera : T_body_camera->inverse();
  gt.trajectory = transformed(gt.trajectory, T_gt_est);
  gt.frame = est.frame;
  return std::string(to_string(est.frame)) + " poses (ground truth converted from " +
         (est.frame == PoseFrame::kCamera ? "body" : "camera") + " with T_body_camera)";
}

}  // namespace kestrel::eval
