#pragma once
// Readers for the text files of a TUM RGB-D sequence folder: the image lists (rgb.txt,
// depth.txt: "timestamp filename") and the Kinect accelerometer log (accelerometer.txt:
// "timestamp ax ay az"). groundtruth.txt is read by common/trajectory.h.
//
// Invariants of what these return: time stamps are exact microseconds (common/time.h) and
// strictly increasing, values are finite. Anything else throws InputError naming the file
// and line; '#' lines and blank lines are skipped.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/camera.h"

namespace kestrel::tum {

/// One line of rgb.txt or depth.txt.
struct ImageEntry {
  int64_t utime = 0;
  std::string file;  ///< as listed, relative to the sequence folder
  int line = 0;      ///< 1-based line in the list, for error messages
};

/// One line of accelerometer.txt: specific force in m/s^2, on the Kinect accelerometer's own
/// axes as TUM recorded them (see README.md "Accelerometer axes").
struct AccelerometerSample {
  int64_t utime = 0;
  Eigen::Vector3d accel_kinect = Eigen::Vector3d::Zero();
};

/// Reads rgb.txt or depth.txt. Throws InputError for a missing file, a malformed line, a time
/// stamp not after the previous one, or a list without any entry.
std::vector<ImageEntry> read_image_list(const std::string& path);

/// Reads accelerometer.txt (an empty log is allowed). Throws InputError for a missing file, a
/// malformed line, a non-finite value or a time stamp not after the previous one.
std::vector<AccelerometerSample> read_accelerometer(const std::string& path);

/// camera.txt, kestrel's own addition to the folder: which camera took it, for a recording
/// whose folder name says nothing (kestrel-sim writes one; a user may write one for a recording
/// of any other camera). The first data line is "fx fy cx cy width height", optionally followed
/// by the lens distortion "k1 k2 p1 p2 k3" (OpenCV's, of the raw images); then, each at most
/// once, "T_body_camera x y z qx qy qz qw" (the camera in the vehicle's body frame, as the
/// simulator mounted it; a quaternion of norm 1 within 1e-3) and "sensor NAME" (a built-in
/// sensor profile, which the frames then name: sensors/profiles/).
struct CameraFile {
  PinholeCamera camera;
  std::optional<Eigen::Isometry3d> T_body_camera;
  std::string sensor;  ///< "" when the file names none
};

/// Reads camera.txt. Throws InputError naming the file and line for a missing file, a malformed
/// or repeated line, an unknown key, a non-finite or impossible value (focal lengths and sizes
/// must be positive, sizes whole numbers up to 16384; check_plausible_camera, common/camera.h),
/// a sensor that is no built-in profile, or a file without the intrinsics line.
CameraFile read_camera_file(const std::string& path);

}  // namespace kestrel::tum
