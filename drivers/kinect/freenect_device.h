#pragma once
// One Kinect (v1) through libfreenect's C API: RGB (FREENECT_VIDEO_RGB) and raw 11-bit depth
// (FREENECT_DEPTH_11BIT) at 640x480, and the accelerometer.
//
// The same binary drives a real Kinect (libfreenect + libusb) or replays a recording through
// Debian's fakenect library (LD_LIBRARY_PATH=/usr/lib/<arch>/fakenect, FAKENECT_PATH=<dump>):
// fakenect exports the same symbols, so nothing here changes. Because fakenect calls exit(1)
// deep inside freenect_process_events when its dump is missing, the constructor checks
// FAKENECT_PATH first when it finds itself linked against fakenect, and reports a clear error.
//
// Frame callbacks run inside process_events() on the calling thread; the buffers they get
// are only valid during the call.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>

struct _freenect_context;
struct _freenect_device;

namespace kestrel::kinect {

/// No Kinect, or it cannot be opened or started (exit code kExitUnavailable).
class DeviceUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class FreenectDevice {
 public:
  using FrameCallback = std::function<void(const void* data, uint32_t device_ticks)>;

  /// Opens device `index` and starts both streams. Throws DeviceUnavailable if there is no
  /// such Kinect or it fails to start, InputError for a missing or broken fakenect dump.
  FreenectDevice(int index, FrameCallback on_rgb, FrameCallback on_depth);
  ~FreenectDevice();
  FreenectDevice(const FreenectDevice&) = delete;
  FreenectDevice& operator=(const FreenectDevice&) = delete;

  /// Handles pending USB events (calls the frame callbacks), waiting at most timeout_ms.
  /// False when libfreenect fails: the device is gone, or a fakenect dump has ended.
  bool process_events(int timeout_ms);

  /// Reads the accelerometer now: specific force in m/s^2 on its own axes (accelerometer.h);
  /// empty if the read fails.
  std::optional<Eigen::Vector3d> accelerometer();

  /// True when the libfreenect in use is fakenect (a recording, not a device).
  bool is_fakenect() const { return fakenect_; }
  /// The shared object that provides libfreenect, for the log.
  const std::string& library() const { return library_; }

 private:
  static void on_video(_freenect_device* dev, void* data, uint32_t timestamp);
  static void on_depth(_freenect_device* dev, void* data, uint32_t timestamp);
  void shutdown();

  FrameCallback on_rgb_;
  FrameCallback on_depth_;
  _freenect_context* context_ = nullptr;
  _freenect_device* device_ = nullptr;
  bool fakenect_ = false;
  std::string library_;
};

}  // namespace kestrel::kinect
