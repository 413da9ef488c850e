#include "drivers/tum/tum_lists.h"

#include <cmath>
#include <fstream>

#include "common/error.h"
#include "common/text.h"
#include "common/time.h"
#include "sensors/builtin_profiles.h"

namespace kestrel::tum {
namespace {

// Calls `on_line(fields, line_no, line)` for every line that is neither blank nor a comment.
template <class OnLine>
void for_each_data_line(const std::string& path, const char* what, OnLine on_line) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open " + what);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (is_comment_or_blank(line)) continue;
    on_line(split_fields(line), line_no, line);
  }
  if (in.bad()) throw InputError(path + ": read error");
}

int64_t parse_stamp(const std::string& path, int line_no, std::string_view token,
                    int64_t previous, bool has_previous) {
  const auto utime = parse_seconds(token);
  if (!utime) {
    throw InputError(at_line(path, line_no, "bad timestamp '" + std::string(token) + "'"));
  }
  if (has_previous && *utime <= previous) {
    throw InputError(at_line(path, line_no, "timestamp " + std::string(token) +
                                                " is not after the previous one (" +
                                                format_seconds(previous) + ")"));
  }
  return *utime;
}

}  // namespace

std::vector<ImageEntry> read_image_list(const std::string& path) {
  std::vector<ImageEntry> entries;
  for_each_data_line(path, "image list",
                     [&](const std::vector<std::string_view>& f, int line_no, const std::string& line) {
                       if (f.size() != 2) {
                         throw InputError(at_line(
                             path, line_no, "expected 'timestamp filename', got '" + line + "'"));
                       }
                       const bool has_prev = !entries.empty();
                       const int64_t utime = parse_stamp(path, line_no, f[0],
                                                         has_prev ? entries.back().utime : 0, has_prev);
                       entries.push_back({utime, std::string(f[1]), line_no});
                     });
  if (entries.empty()) throw InputError(path + ": lists no images");
  return entries;
}

std::vector<AccelerometerSample> read_accelerometer(const std::string& path) {
  std::vector<AccelerometerSample> samples;
  for_each_data_line(
      path, "accelerometer log",
      [&](const std::vector<std::string_view>& f, int line_no, const std::string& line) {
        Eigen::Vector3d a;
        bool numbers = f.size() == 4;
        for (int i = 0; numbers && i < 3; ++i) {
          const auto v = parse_double(f[i + 1]);
          numbers = v.has_value();
          if (numbers) a[i] = *v;
        }
        if (!numbers) {
          throw InputError(at_line(path, line_no, "expected 'timestamp ax ay az', got '" + line + "'"));
        }
        if (!a.allFinite()) throw InputError(at_line(path, line_no, "non-finite acceleration"));
        const bool has_prev = !samples.empty();
        const int64_t utime =
            parse_stamp(path, line_no, f[0], has_prev ? samples.back().utime : 0, has_prev);
        samples.push_back({utime, a});
      });
  return samples;
}

CameraFile read_camera_file(const std::string& path) {
  CameraFile file;
  bool have_camera = false, have_pose = false;
  const auto numbers = [&](const std::vector<std::string_view>& f, size_t from, int line_no) {
    std::vector<double> v;
    for (size_t i = from; i < f.size(); ++i) {
      const auto x = parse_double(f[i]);
      if (!x || !std::isfinite(*x))
        throw InputError(at_line(path, line_no, "'" + std::string(f[i]) + "' is not a finite number"));
      v.push_back(*x);
    }
    return v;
  };
  for_each_data_line(path, "camera file", [&](const std::vector<std::string_view>& f, int line_no, const std::string& line) {
    if (f[0] == "sensor") {
      if (f.size() != 2) throw InputError(at_line(path, line_no, "expected 'sensor NAME', got '" + line + "'"));
      if (!file.sensor.empty()) throw InputError(at_line(path, line_no, "a second 'sensor' line"));
      // A name written on purpose: a misspelt one is an error, not the silent `default` an
      // unknown camera on the wire gets.
      std::string names;
      for (const sensors::SensorProfile& p : sensors::builtin_profiles()) {
        if (p.name == f[1]) file.sensor = p.name;
        names += (names.empty() ? "" : ", ") + p.name;
      }
      if (file.sensor.empty())
        throw InputError(at_line(path, line_no, "sensor '" + std::string(f[1]) + "' is not a built-in profile (" + names + ")"));
      return;
    }
    if (f[0] == "T_body_camera") {
      if (f.size() != 8)
        throw InputError(at_line(path, line_no, "expected 'T_body_camera x y z qx qy qz qw', got '" + line + "'"));
      if (have_pose) throw InputError(at_line(path, line_no, "a second 'T_body_camera' line"));
      const std::vector<double> v = numbers(f, 1, line_no);
      const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
      if (std::abs(q.norm() - 1.0) > 1e-3)
        throw InputError(at_line(path, line_no, "the quaternion's norm is " + std::to_string(q.norm()) + ", not 1"));
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.linear() = q.normalized().toRotationMatrix();
      T.translation() << v[0], v[1], v[2];
      file.T_body_camera = T;
      have_pose = true;
      return;
    }
    if (have_camera) throw InputError(at_line(path, line_no, "unknown line '" + line + "' (sensor, T_body_camera)"));
    if (f.size() != 6 && f.size() != 11) {
      throw InputError(at_line(path, line_no, "expected 'fx fy cx cy width height [k1 k2 p1 p2 k3]', got '" + line + "'"));
    }
    const std::vector<double> v = numbers(f, 0, line_no);
    for (int i : {4, 5}) {
      if (!(v[static_cast<size_t>(i)] >= 1 && v[static_cast<size_t>(i)] <= 16384 &&
            v[static_cast<size_t>(i)] == std::floor(v[static_cast<size_t>(i)])))
        throw InputError(at_line(path, line_no, "the image size must be whole numbers from 1 to 16384"));
    }
    if (!(v[0] > 0 && v[1] > 0)) throw InputError(at_line(path, line_no, "the focal lengths must be > 0"));
    PinholeCamera c = PinholeCamera::vga(v[0], v[1], v[2], v[3]);
    c.width = static_cast<int>(v[4]);
    c.height = static_cast<int>(v[5]);
    if (v.size() == 11) c.distortion = {v[6], v[7], v[8], v[9], v[10]};
    try {
      c.validate("intrinsics");
    } catch (const std::exception& e) {
      throw InputError(at_line(path, line_no, e.what()));
    }
    file.camera = c;
    have_camera = true;
  });
  if (!have_camera) throw InputError(path + ": no 'fx fy cx cy width height' line");
  check_plausible_camera(file.camera, file.T_body_camera.value_or(Eigen::Isometry3d::Identity()), path.c_str());
  return file;
}

}  // namespace kestrel::tum
