#include "common/trajectory.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <stdexcept>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/geometry/se3.h"
#include "common/text.h"
#include "common/time.h"

namespace kestrel {

Trajectory::Trajectory(std::vector<StampedPose> poses) : poses_(std::move(poses)) {
  std::stable_sort(poses_.begin(), poses_.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.utime < b.utime; });
  for (size_t i = 1; i < poses_.size(); ++i) {
    if (poses_[i].utime == poses_[i - 1].utime)
      throw InputError("trajectory has two poses at " + format_seconds(poses_[i].utime));
  }
}

void Trajectory::push_back(int64_t utime, const Eigen::Isometry3d& T) {
  if (!poses_.empty() && utime <= poses_.back().utime)
    throw std::invalid_argument("Trajectory::push_back: utime not increasing");
  poses_.push_back({utime, T});
}

std::optional<Eigen::Isometry3d> Trajectory::at(int64_t utime, int64_t max_gap_us) const {
  auto it = std::lower_bound(poses_.begin(), poses_.end(), utime,
                             [](const StampedPose& p, int64_t t) { return p.utime < t; });
  if (it != poses_.end() && it->utime == utime) return it->T;
  if (it == poses_.begin() || it == poses_.end()) return std::nullopt;
  const StampedPose& a = *(it - 1);
  const StampedPose& b = *it;
  if (utime - a.utime > max_gap_us || b.utime - utime > max_gap_us) return std::nullopt;
  const double s = static_cast<double>(utime - a.utime) / static_cast<double>(b.utime - a.utime);
  return se3::interpolate(a.T, b.T, s);
}

Trajectory read_tum_trajectory(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open trajectory file");
  Trajectory trajectory;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (is_comment_or_blank(line)) continue;
    const auto fields = split_fields(line);
    double v[7];
    bool numbers = fields.size() == 8;
    for (int i = 0; numbers && i < 7; ++i) {
      const auto x = parse_double(fields[i + 1]);
      numbers = x.has_value();
      if (numbers) v[i] = *x;
    }
    if (!numbers) {
      throw InputError(
          at_line(path, line_no, "expected 'timestamp tx ty tz qx qy qz qw', got '" + line + "'"));
    }
    const std::string stamp(fields[0]);
    const auto utime = parse_seconds(stamp);
    if (!utime) throw InputError(at_line(path, line_no, "bad timestamp '" + stamp + "'"));
    for (double x : v) {
      if (!std::isfinite(x)) throw InputError(at_line(path, line_no, "non-finite value"));
    }
    Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
    if (std::abs(q.norm() - 1.0) > 1e-2)
      throw InputError(at_line(path, line_no, "quaternion is not of unit length"));
    if (!trajectory.empty() && *utime <= trajectory.poses().back().utime) {
      throw InputError(at_line(path, line_no,
                               "timestamp " + stamp + " is not after the previous one"));
    }
    trajectory.push_back(*utime, se3::make(q, Eigen::Vector3d(v[0], v[1], v[2])));
  }
  if (in.bad()) throw InputError(path + ": read error");
  return trajectory;
}

void write_tum_trajectory(const std::string& path, const Trajectory& trajectory) {
  // Atomically: a run that fails half-way leaves the previous trajectory, not a cut one.
  AtomicFile file(path);
  std::ostream& out = file.stream();
  out << "# timestamp tx ty tz qx qy qz qw\n" << std::setprecision(9);
  for (const StampedPose& p : trajectory.poses()) {
    const Eigen::Quaterniond q(p.T.linear());
    const Eigen::Vector3d& t = p.T.translation();
    out << format_seconds(p.utime) << ' ' << t.x() << ' ' << t.y() << ' ' << t.z() << ' ' << q.x()
        << ' ' << q.y() << ' ' << q.z() << ' ' << q.w() << '\n';
  }
  file.commit();
}

}  // namespace kestrel
