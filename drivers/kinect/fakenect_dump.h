#pragma once
// Writes a recording in the format that libfreenect's "fakenect" replays (the libfreenect.so
// in /usr/lib/<arch>/fakenect/ of Debian's libfreenect 0.5.3; FAKENECT_PATH names the folder),
// so that the unchanged Kinect driver can be run on known data.
//
// The format, as fakenect 0.5.3 reads it (learnt from libfreenect's fakenect/fakenect.c and
// fakenect/record.c, and checked against the Debian library):
//  * INDEX.txt lists the files in replay order, one name per line. fakenect parses each name
//    as "<type>-<seconds>-<ticks>...": type 'r' (RGB), 'd' (depth) or 'a' (accelerometer);
//    seconds = recording time, which paces the replay (it sleeps the differences); ticks =
//    the device time stamp handed to the frame callbacks (32-bit, 60 MHz).
//  * r-*.ppm: one header line "P6 640 480 255\n", then 640*480*3 bytes in R,G,B order.
//  * d-*.pgm: one header line "P5 640 480 65535\n", then 640*480 uint16 raw 11-bit values in
//    the host's byte order (little-endian; not the big-endian of a standard PGM: fakenect
//    copies the bytes as they are).
//  * a-*.dump: the bytes of a freenect_raw_tilt_state (raw accelerometer counts, tilt angle,
//    tilt status), any other size is ignored with a warning.
// fakenect replays the index once; at its end freenect_process_events returns -1 for good.
// A missing INDEX.txt or listed file makes fakenect exit(1) inside freenect_process_events.
//
// Invariant: entries are added in non-decreasing time order (fakenect replays the index in
// file order; a step back in time would only be skipped, not reordered).

#include <Eigen/Core>
#include <cstdint>
#include <cstdio>
#include <string>

#include <opencv2/core/mat.hpp>

namespace kestrel::kinect {

/// The device time stamp fakenect reports for a recording time: 60 ticks per microsecond,
/// modulo 2^32 (like the Kinect's own clock, it wraps every 71.6 s).
uint32_t device_ticks(int64_t utime);

class FakenectDumpWriter {
 public:
  /// Creates `folder` if needed; throws InputError if it cannot, or if it already holds an
  /// INDEX.txt (a dump is never overwritten).
  explicit FakenectDumpWriter(const std::string& folder);
  ~FakenectDumpWriter();
  FakenectDumpWriter(const FakenectDumpWriter&) = delete;
  FakenectDumpWriter& operator=(const FakenectDumpWriter&) = delete;

  /// rgb: CV_8UC3, R,G,B, 640x480.
  void add_rgb(int64_t utime, const cv::Mat& rgb);
  /// raw: CV_16UC1 raw 11-bit depth in the IR camera, 640x480 (2047 = no reading).
  void add_depth(int64_t utime, const cv::Mat& raw);
  /// Specific force in m/s^2 on the accelerometer's own axes (accelerometer.h), stored as
  /// raw counts.
  void add_accel(int64_t utime, const Eigen::Vector3d& accel);
  /// Flushes INDEX.txt; throws InputError on a write error.
  void close();

  int64_t entries() const { return entries_; }

 private:
  std::string add_entry(char type, int64_t utime, const char* extension);
  void write_file(const std::string& name, const std::string& header, const void* data, size_t size);

  std::string folder_;
  std::FILE* index_ = nullptr;
  int64_t last_utime_ = 0;
  int64_t entries_ = 0;
};

}  // namespace kestrel::kinect
