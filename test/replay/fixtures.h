#pragma once
// What the replay, launch, monitor and codec tests share: synthetic RGB-D logs with known
// content, a private network per test process, child processes in the background, and an
// LCM tap that watches the traffic from inside the test.

#include <sys/types.h>

#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "common/rgbd_frame.h"
#include "common/transport/log_file.h"
#include "kestrel/process_status_t.hpp"
#include "test/support/test_support.h"

namespace kestrel::test {

/// Frame `i` of a small synthetic camera: colour gradients that drift with i, a bright square
/// that moves, pseudo-random texture, depth that varies with i and has holes (0).
RgbdFrame synthetic_frame(int i, int width = 64, int height = 48);

struct TestLogSpec {
  int frames = 30;
  int width = 64;
  int height = 48;
  int imu_per_frame = 3;        ///< IMU samples between frames
  bool ground_truth = true;     ///< one GROUND_TRUTH per frame
  int64_t start_utime = 1'000'000'000;
  int64_t frame_period_us = 33'333;
};

/// Writes CAMERA_RGBD (raw colour and depth), IMU and GROUND_TRUTH events in time order,
/// each stamped with its message utime. Returns the number of events per channel.
std::map<std::string, int64_t> write_test_log(const std::filesystem::path& path,
                                              const TestLogSpec& spec = {});

/// Every intact event of a log, in file order.
std::vector<transport::LogEvent> read_log(const std::filesystem::path& path);
/// A file's bytes, and writing them back (to damage a log on purpose).
std::vector<uint8_t> read_bytes(const std::filesystem::path& path);
void write_bytes(const std::filesystem::path& path, const std::vector<uint8_t>& bytes);

/// Moves this test process (and every child it starts) into a private network namespace
/// with multicast on loopback; once per process. False if that is impossible here.
bool isolate_this_process();

/// Skips the current test unless it could be isolated (never sends multicast outside).
#define KESTREL_REQUIRE_ISOLATION()                                                       \
  if (!::kestrel::test::isolate_this_process())                                           \
  KESTREL_SKIP_ENVIRONMENT() << "cannot create a private network namespace here (needs "  \
                                "root or unprivileged user namespaces)"

/// A child process running in the background, in its own process group, with stdout and
/// stderr going to files; killed (with its group) at destruction.
class Background {
 public:
  Background(const std::vector<std::string>& argv, const std::filesystem::path& output_dir,
             const std::string& label);
  ~Background();
  Background(const Background&) = delete;
  Background& operator=(const Background&) = delete;

  pid_t pid() const { return pid_; }
  void signal(int sig) const;
  /// Exit code (or 128 + signal) once it exits within `timeout_s`, else empty.
  std::optional<int> wait_exit(double timeout_s);
  bool running();
  std::string out() const;
  std::string err() const;
  /// Waits until stdout (or stderr) contains `needle`.
  bool wait_for_output(const std::string& needle, double timeout_s, bool in_stderr = false);

 private:
  pid_t pid_ = -1;
  std::optional<int> exit_code_;
  std::filesystem::path out_path_, err_path_;
};

/// Receives everything on the LCM URL on a thread of its own: counts per channel, the
/// latest heartbeat per process, and an optional hook per message.
class LcmTap {
 public:
  explicit LcmTap(const std::string& url = "");
  ~LcmTap();
  LcmTap(const LcmTap&) = delete;
  LcmTap& operator=(const LcmTap&) = delete;

  int64_t count(const std::string& channel) const;
  std::optional<kestrel::process_status_t> status(const std::string& process) const;
  /// Called on the tap's thread for each message with its channel and the channel's count.
  void set_hook(std::function<void(const std::string&, int64_t)> hook);
  /// Waits until `ready()` holds, re-checked after each message and every 50 ms.
  bool wait_until(const std::function<bool()>& ready, double timeout_s);
  /// Waits until every named process has sent a heartbeat.
  bool wait_for_processes(const std::vector<std::string>& names, double timeout_s);

 private:
  static void on_message(const lcm::ReceiveBuffer* rbuf, const std::string& channel, LcmTap* self);
  lcm::LCM lcm_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::map<std::string, int64_t> counts_;
  std::map<std::string, kestrel::process_status_t> statuses_;
  std::function<void(const std::string&, int64_t)> hook_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace kestrel::test
