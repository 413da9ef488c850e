#include "drivers/tum/tum_sequence.h"

#include <filesystem>
#include <stdexcept>

#include "common/error.h"
#include "common/time.h"
#include "drivers/tum/association.h"

namespace kestrel::tum {
namespace fs = std::filesystem;
namespace {

// "3 RGB images from 1305031229.528748 to 1305031229.595414 s", for an association that failed.
std::string span(const std::vector<ImageEntry>& list, const char* what) {
  return std::to_string(list.size()) + " " + what + " images from " + format_seconds(list.front().utime) +
         " to " + format_seconds(list.back().utime) + " s";
}

}  // namespace

TumSequence::TumSequence(const std::string& folder, SequenceOptions options)
    : folder_(folder), to_mm_(options.depth_scale_correction) {
  if (options.max_time_difference_us < 0)
    throw std::invalid_argument("max time difference must be >= 0");
  std::error_code ec;
  if (!fs::is_directory(folder_, ec)) throw InputError(folder_ + ": no such sequence folder");

  camera_model_ = detect_camera(folder_);
  camera_ = camera_intrinsics(camera_model_);
  const std::optional<CameraFile> file = camera_file_of(folder_);
  sensor_ = sensor_model_of(camera_model_, file);
  if (file) {
    camera_ = file->camera;
    has_camera_file_ = true;
  }
  if (options.intrinsics) {
    PinholeCamera c = *options.intrinsics;
    c.width = camera_.width;
    c.height = camera_.height;
    c.validate("intrinsics");
    camera_ = c;
  }

  rgb_list_ = (fs::path(folder_) / "rgb.txt").string();
  depth_list_ = (fs::path(folder_) / "depth.txt").string();
  rgb_ = read_image_list(rgb_list_);
  depth_ = read_image_list(depth_list_);
  check_images_exist(rgb_, rgb_list_);
  check_images_exist(depth_, depth_list_);

  const std::string gt_path = (fs::path(folder_) / "groundtruth.txt").string();
  has_ground_truth_ = fs::exists(gt_path, ec);
  if (has_ground_truth_) ground_truth_ = read_tum_trajectory(gt_path);
  const std::string accel_path = (fs::path(folder_) / "accelerometer.txt").string();
  has_accelerometer_ = fs::exists(accel_path, ec);
  if (has_accelerometer_) accelerometer_ = read_accelerometer(accel_path);

  std::vector<int64_t> rgb_times, depth_times;
  rgb_times.reserve(rgb_.size());
  depth_times.reserve(depth_.size());
  for (const auto& e : rgb_) rgb_times.push_back(e.utime);
  for (const auto& e : depth_) depth_times.push_back(e.utime);
  const Association association = associate(rgb_times, depth_times, options.max_time_difference_us);
  if (association.pairs.empty()) {
    // Every reader of the folder would run over nothing and finish as if all were well. Both
    // lists are non-empty here (read_image_list), so their spans say how far apart they are.
    throw InputError(folder_ + ": no RGB image has a depth image within the association tolerance of " +
                     format_seconds(options.max_time_difference_us) + " s (" + span(rgb_, "RGB") + ", " +
                     span(depth_, "depth") + ")");
  }
  frames_.reserve(association.pairs.size());
  for (const auto& p : association.pairs) frames_.push_back({p.a, p.b});
  stats_.rgb_images = rgb_.size();
  stats_.depth_images = depth_.size();
  stats_.frames = frames_.size();
  stats_.unmatched_rgb = association.unmatched_a;
  stats_.unused_depth = association.unused_b;
  stats_.shared_depth = association.shared_b;
}

std::string TumSequence::path_of(const ImageEntry& e) const {
  return (fs::path(folder_) / e.file).string();
}

void TumSequence::check_images_exist(const std::vector<ImageEntry>& list,
                                     const std::string& list_path) const {
  std::error_code ec;
  for (const ImageEntry& e : list) {
    if (!fs::is_regular_file(path_of(e), ec)) {
      throw InputError(at_line(list_path, e.line, "listed image '" + e.file + "' does not exist"));
    }
  }
}

RgbdFrame TumSequence::frame(size_t i) const {
  const FrameRef& ref = frames_.at(i);
  const ImageEntry& rgb = rgb_[ref.rgb];
  const ImageEntry& depth = depth_[ref.depth];
  RgbdFrame f;
  f.utime = rgb.utime;
  f.depth_utime = depth.utime;
  f.seq = static_cast<int64_t>(ref.rgb);
  f.camera = camera_;
  f.sensor = sensor_;
  f.rgb = load_rgb(path_of(rgb), camera_.width, camera_.height, {rgb_list_, rgb.line});
  f.depth_mm = to_mm_(
      load_depth_raw(path_of(depth), camera_.width, camera_.height, {depth_list_, depth.line}));
  return f;
}

}  // namespace kestrel::tum
