#include "test/replay/fixtures.h"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fcntl.h>
#include <fstream>
#include <sstream>

#include "common/geometry/se3.h"
#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/lcm_url.h"
#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/imu_t.hpp"
#include "test/support/test_support.h"
#include "tools/launch/isolation.h"

namespace kestrel::test {
namespace {

uint32_t mix(uint32_t x) {  // a small integer hash: texture that JPEG cannot flatten
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

}  // namespace

RgbdFrame synthetic_frame(int i, int width, int height) {
  RgbdFrame f;
  f.seq = i;
  f.utime = 1'000'000'000 + int64_t{i} * 33'333;
  f.depth_utime = f.utime + 1'000;
  f.camera.width = width;
  f.camera.height = height;
  f.camera.fx = f.camera.fy = 0.8 * width;
  f.camera.cx = 0.5 * (width - 1);
  f.camera.cy = 0.5 * (height - 1);
  // Camera looking forward: optical z along body x, optical x along body -y.
  Eigen::Matrix3d R_body_camera;
  R_body_camera << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  f.T_body_camera = se3::make(R_body_camera, Eigen::Vector3d(0.1, 0.0, -0.02));
  f.rgb.create(height, width, CV_8UC3);
  f.depth_mm.create(height, width, CV_16UC1);
  const int square = (i * 3) % std::max(1, width - 8);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      auto* px = f.rgb.ptr<uint8_t>(y) + 3 * x;
      const uint32_t noise = mix(static_cast<uint32_t>((i * height + y) * width + x));
      const bool in_square = x >= square && x < square + 8 && y >= 8 && y < 16;
      px[0] = in_square ? 255 : static_cast<uint8_t>(x * 4 + i * 7);
      px[1] = in_square ? 255 : static_cast<uint8_t>(y * 5 + i * 3);
      px[2] = static_cast<uint8_t>(noise & 0x3f);
      f.depth_mm.at<uint16_t>(y, x) =
          (x + y + i) % 17 == 0 ? 0 : static_cast<uint16_t>(500 + 10 * x + 20 * i + (noise >> 28));
    }
  }
  return f;
}

std::map<std::string, int64_t> write_test_log(const std::filesystem::path& path,
                                              const TestLogSpec& spec) {
  transport::LogWriter log(path);
  std::map<std::string, int64_t> counts;
  const int64_t imu_period = spec.frame_period_us / std::max(1, spec.imu_per_frame);
  int64_t imu_seq = 0;
  for (int i = 0; i < spec.frames; ++i) {
    const int64_t t = spec.start_utime + i * spec.frame_period_us;
    RgbdFrame frame = synthetic_frame(i, spec.width, spec.height);
    frame.utime = t;
    frame.depth_utime = t + 1'000;
    log.write_message(channel::kCameraRgbd, t, transport::encode_rgbd(frame));
    ++counts[channel::kCameraRgbd];
    if (spec.ground_truth) {
      kestrel::ground_truth_t gt{};
      gt.utime = t;
      gt.frame = kestrel::ground_truth_t::FRAME_CAMERA;
      gt.T_world_frame = transport::to_message(
          se3::make(Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * i, Eigen::Vector3d::UnitZ())),
                    Eigen::Vector3d(0.02 * i, 0.0, 1.0)));
      log.write_message(channel::kGroundTruth, t, gt);
      ++counts[channel::kGroundTruth];
    }
    for (int k = 0; k < spec.imu_per_frame; ++k) {
      kestrel::imu_t imu{};
      imu.utime = t + k * imu_period + 500;
      imu.seq = imu_seq++;
      imu.fields = kestrel::imu_t::HAS_GYRO | kestrel::imu_t::HAS_ACCEL;
      imu.angular_velocity[2] = 0.3;
      imu.linear_acceleration[2] = 9.81 + 0.01 * k;
      log.write_message(channel::kImu, imu.utime, imu);
      ++counts[channel::kImu];
    }
  }
  log.close();
  return counts;
}

std::vector<transport::LogEvent> read_log(const std::filesystem::path& path) {
  transport::LogReader reader(path);
  std::vector<transport::LogEvent> events;
  while (auto e = reader.next()) events.push_back(std::move(*e));
  return events;
}

std::vector<uint8_t> read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void write_bytes(const std::filesystem::path& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

bool isolate_this_process() {
  static const bool isolated = [] {
    try {
      launch::enter_private_network();
      return true;
    } catch (const launch::IsolationError&) {
      return false;
    }
  }();
  return isolated;
}

Background::Background(const std::vector<std::string>& argv, const std::filesystem::path& dir,
                       const std::string& label)
    : out_path_(dir / (label + ".out")), err_path_(dir / (label + ".err")) {
  const int out = ::open(out_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  const int err = ::open(err_path_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (out < 0 || err < 0) throw std::runtime_error("cannot create output files in " + dir.string());
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_ = ::fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    ::setpgid(0, 0);
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // never outlive a crashed test
    ::dup2(out, 1);
    ::dup2(err, 2);
    ::execvp(args[0], args.data());
    _exit(127);
  }
  ::setpgid(pid_, pid_);
  ::close(out);
  ::close(err);
}

Background::~Background() {
  if (running()) {
    signal(SIGTERM);
    if (!wait_exit(5.0)) {
      signal(SIGKILL);
      wait_exit(5.0);
    }
  }
  ::kill(-pid_, SIGKILL);  // anything it left behind in its group
}

void Background::signal(int sig) const { ::kill(pid_, sig); }

std::optional<int> Background::wait_exit(double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!exit_code_) {
    int status = 0;
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      break;
    }
    if (std::chrono::steady_clock::now() >= deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return exit_code_;
}

bool Background::running() { return !wait_exit(0.0).has_value(); }

std::string Background::out() const { return read_file(out_path_); }
std::string Background::err() const { return read_file(err_path_); }

bool Background::wait_for_output(const std::string& needle, double timeout_s, bool in_stderr) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (true) {
    if ((in_stderr ? err() : out()).find(needle) != std::string::npos) return true;
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

LcmTap::LcmTap(const std::string& url) : lcm_(transport::resolve_lcm_url(url)) {
  if (!lcm_.good()) throw std::runtime_error("LcmTap: cannot start LCM");
  lcm::Subscription* sub = lcm_.subscribeFunction(".*", &LcmTap::on_message, this);
  sub->setQueueCapacity(0);
  thread_ = std::thread([this] {
    while (!stop_) lcm_.handleTimeout(50);
  });
}

LcmTap::~LcmTap() {
  stop_ = true;
  thread_.join();
}

void LcmTap::on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel, LcmTap* self) {
  std::function<void(const std::string&, int64_t)> hook;
  int64_t n = 0;
  {
    std::lock_guard<std::mutex> lock(self->mutex_);
    n = ++self->counts_[channel];
    if (channel == channel::kProcessStatus) {
      kestrel::process_status_t s;
      if (s.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) > 0) self->statuses_[s.name] = s;
    }
    hook = self->hook_;
  }
  if (hook) hook(channel, n);
  self->changed_.notify_all();
}

int64_t LcmTap::count(const std::string& channel) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = counts_.find(channel);
  return it == counts_.end() ? 0 : it->second;
}

std::optional<kestrel::process_status_t> LcmTap::status(const std::string& process) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = statuses_.find(process);
  if (it == statuses_.end()) return std::nullopt;
  return it->second;
}

void LcmTap::set_hook(std::function<void(const std::string&, int64_t)> hook) {
  std::lock_guard<std::mutex> lock(mutex_);
  hook_ = std::move(hook);
}

bool LcmTap::wait_until(const std::function<bool()>& ready, double timeout_s) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!ready()) {
    if (std::chrono::steady_clock::now() >= deadline) return false;
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait_for(lock, std::chrono::milliseconds(50));
  }
  return true;
}

bool LcmTap::wait_for_processes(const std::vector<std::string>& names, double timeout_s) {
  return wait_until(
      [&] {
        for (const auto& n : names)
          if (!status(n)) return false;
        return true;
      },
      timeout_s);
}

}  // namespace kestrel::test
