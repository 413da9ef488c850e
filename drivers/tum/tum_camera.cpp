#include "drivers/tum/tum_camera.h"

#include <filesystem>

namespace kestrel::tum {

TumCamera detect_camera(const std::string& folder) {
  // "a/b/" has an empty filename(); the folder's own name is what TUM puts the camera in.
  std::filesystem::path p = std::filesystem::path(folder).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  const std::string name = p.filename().string();
  if (name.find("freiburg1") != std::string::npos) return TumCamera::kFreiburg1;
  if (name.find("freiburg2") != std::string::npos) return TumCamera::kFreiburg2;
  if (name.find("freiburg3") != std::string::npos) return TumCamera::kFreiburg3;
  return TumCamera::kUnknown;
}

PinholeCamera camera_intrinsics(TumCamera camera) {
  switch (camera) {
    case TumCamera::kFreiburg1:
    {
      PinholeCamera c = PinholeCamera::vga(517.3, 516.5, 318.6, 255.3);
      c.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
      return c;
    }
    case TumCamera::kFreiburg2:
    {
      PinholeCamera c = PinholeCamera::vga(520.9, 521.0, 325.1, 249.7);
      c.distortion = {0.2312, -0.7849, -0.0033, -0.0001, 0.9172};
      return c;
    }
    case TumCamera::kFreiburg3:
      return PinholeCamera::vga(535.4, 539.2, 320.1, 247.6);
    case TumCamera::kUnknown:
      break;
  }
  return PinholeCamera::vga(525.0, 525.0, 319.5, 239.5);
}

const char* camera_name(TumCamera camera) {
  switch (camera) {
    case TumCamera::kFreiburg1:
      return "freiburg1";
    case TumCamera::kFreiburg2:
      return "freiburg2";
    case TumCamera::kFreiburg3:
      return "freiburg3";
    case TumCamera::kUnknown:
      break;
  }
  return "unknown (ROS default intrinsics)";
}

const char* sensor_model_of(TumCamera camera) {
  return camera == TumCamera::kFreiburg1 ? sensor_model::kKinect1 : "";
}

std::optional<CameraFile> camera_file_of(const std::string& folder) {
  const std::filesystem::path path = std::filesystem::path(folder) / "camera.txt";
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return std::nullopt;
  return read_camera_file(path.string());
}

std::string sensor_model_of(TumCamera camera, const std::optional<CameraFile>& file) {
  return file && !file->sensor.empty() ? file->sensor : sensor_model_of(camera);
}

std::string sensor_model_of_folder(const std::string& folder) {
  return sensor_model_of(detect_camera(folder), camera_file_of(folder));
}

}  // namespace kestrel::tum
