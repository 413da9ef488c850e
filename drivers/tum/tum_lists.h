#pragma once
// Readers for the text files of a TUM RGB-D sequence folder: the image lists (rgb.txt,
// depth.txt: "timestamp filename") and the Kinect accelerometer log (accelerometer.txt:
// "timestamp ax ay az"). groundtruth.txt is read by common/trajectory.h.
//
// Invariants of what these return: time stamps are exact microseconds (common/time.h) and
// strictly increasing, values are finite. Anything else throws InputError naming the file
// and line; '#' lines and blank lines are skipped.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

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

}  // namespace kestrel::tum
