#include "drivers/kinect/freenect_device.h"

#include <dlfcn.h>
#include <libfreenect.h>
#include <spdlog/spdlog.h>
#include <sys/time.h>

#include <cstdlib>
#include <filesystem>

#include "common/error.h"
#include "drivers/kinect/accelerometer.h"

namespace kestrel::kinect {
namespace {

void on_log(freenect_context*, freenect_loglevel level, const char* message) {
  std::string m(message ? message : "");
  while (!m.empty() && (m.back() == '\n' || m.back() == '\r')) m.pop_back();
  if (level <= FREENECT_LOG_ERROR) {
    spdlog::warn("libfreenect: {}", m);
  } else {
    spdlog::debug("libfreenect: {}", m);
  }
}

// Which file provides freenect_init: Debian's fakenect lives in .../fakenect/libfreenect.so.
std::string providing_library() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&freenect_init), &info) == 0 || !info.dli_fname) return "";
  return info.dli_fname;
}

void check_fakenect_dump() {
  const char* path = std::getenv("FAKENECT_PATH");
  if (!path || !*path)
    throw InputError("FAKENECT_PATH is not set: the fakenect library replays the dump folder it names");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(std::filesystem::path(path) / "INDEX.txt", ec))
    throw InputError(std::string(path) + ": not a fakenect dump (no INDEX.txt)");
}

}  // namespace

FreenectDevice::FreenectDevice(int index, FrameCallback on_rgb, FrameCallback on_depth)
    : on_rgb_(std::move(on_rgb)), on_depth_(std::move(on_depth)), library_(providing_library()) {
  fakenect_ = library_.find("fakenect") != std::string::npos;
  if (fakenect_) check_fakenect_dump();

  if (freenect_init(&context_, nullptr) < 0 || !context_) {
    context_ = nullptr;
    throw DeviceUnavailable("cannot initialise libfreenect (no USB access?)");
  }
  freenect_set_log_callback(context_, on_log);
  freenect_set_log_level(context_, FREENECT_LOG_WARNING);
  // Camera and motor only: the audio device needs firmware and is not used.
  freenect_select_subdevices(context_, static_cast<freenect_device_flags>(FREENECT_DEVICE_MOTOR |
                                                                          FREENECT_DEVICE_CAMERA));
  const int count = freenect_num_devices(context_);
  if (count <= index) {
    shutdown();
    throw DeviceUnavailable(count <= 0 ? "no Kinect found"
                                       : "no Kinect number " + std::to_string(index) + " (found " +
                                             std::to_string(count) + ")");
  }
  if (freenect_open_device(context_, &device_, index) < 0) {
    device_ = nullptr;
    shutdown();
    throw DeviceUnavailable("cannot open Kinect number " + std::to_string(index) + " (in use, or no permission?)");
  }
  freenect_set_user(device_, this);
  freenect_set_video_callback(device_, &FreenectDevice::on_video);
  freenect_set_depth_callback(device_, &FreenectDevice::on_depth);
  const freenect_frame_mode video = freenect_find_video_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_VIDEO_RGB);
  const freenect_frame_mode depth = freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_DEPTH_11BIT);
  const bool started = video.is_valid && depth.is_valid && freenect_set_video_mode(device_, video) == 0 &&
                       freenect_set_depth_mode(device_, depth) == 0 && freenect_start_video(device_) == 0 &&
                       freenect_start_depth(device_) == 0;
  if (!started) {
    shutdown();
    throw DeviceUnavailable("the Kinect refused 640x480 RGB + 11-bit depth streaming");
  }
}

FreenectDevice::~FreenectDevice() { shutdown(); }

void FreenectDevice::shutdown() {
  if (device_) {
    freenect_stop_video(device_);
    freenect_stop_depth(device_);
    freenect_close_device(device_);
    device_ = nullptr;
  }
  if (context_) {
    freenect_shutdown(context_);
    context_ = nullptr;
  }
}

void FreenectDevice::on_video(_freenect_device* dev, void* data, uint32_t timestamp) {
  auto* self = static_cast<FreenectDevice*>(freenect_get_user(dev));
  if (self && self->on_rgb_) self->on_rgb_(data, timestamp);
}

void FreenectDevice::on_depth(_freenect_device* dev, void* data, uint32_t timestamp) {
  auto* self = static_cast<FreenectDevice*>(freenect_get_user(dev));
  if (self && self->on_depth_) self->on_depth_(data, timestamp);
}

bool FreenectDevice::process_events(int timeout_ms) {
  // libusb's LIBUSB_ERROR_INTERRUPTED: a signal (e.g. SIGINT, which the caller handles) cut
  // the wait short; the device is fine.
  constexpr int kInterrupted = -10;
  timeval timeout{timeout_ms / 1000, (timeout_ms % 1000) * 1000};
  const int rc = freenect_process_events_timeout(context_, &timeout);
  return rc >= 0 || rc == kInterrupted;
}

std::optional<Eigen::Vector3d> FreenectDevice::accelerometer() {
  if (freenect_update_tilt_state(device_) < 0) return std::nullopt;
  freenect_raw_tilt_state* state = freenect_get_tilt_state(device_);
  if (!state) return std::nullopt;
  Eigen::Vector3d a;
  freenect_get_mks_accel(state, &a.x(), &a.y(), &a.z());
  return a;
}

}  // namespace kestrel::kinect
