#include "test/ros/ros_master.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <thread>

namespace kestrel::test {
namespace {

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string p = path ? path : "";
  size_t start = 0;
  while (start <= p.size()) {
    const size_t end = p.find(':', start);
    const std::string dir = p.substr(start, end == std::string::npos ? std::string::npos : end - start);
    if (!dir.empty() && ::access((dir + "/" + program).c_str(), X_OK) == 0) return true;
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return false;
}

bool accepts(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return false;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool ok = ::connect(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0;
  ::close(fd);
  return ok;
}

}  // namespace

std::string missing_ros_programs() {
  std::string missing;
  for (const char* p : {"roscore", "rosbag"})
    if (!on_path(p)) missing += std::string(missing.empty() ? "" : ", ") + p;
  return missing.empty() ? "" : missing + " not found (Debian's ros-core; ./kestrel test installs it)";
}

std::string use_ros_master(const std::filesystem::path& dir, int port) {
  const std::string uri = "http://127.0.0.1:" + std::to_string(port);
  std::filesystem::create_directories(dir / "ros_home");
  ::setenv("ROS_MASTER_URI", uri.c_str(), 1);
  // Loopback addresses for every node: the namespace has no other interface, and its host name
  // need not resolve there.
  ::setenv("ROS_IP", "127.0.0.1", 1);
  ::unsetenv("ROS_HOSTNAME");
  ::setenv("ROS_HOME", (dir / "ros_home").c_str(), 1);
  ::setenv("ROS_LOG_DIR", (dir / "ros_home" / "log").c_str(), 1);
  return uri;
}

bool start_roscore(LiveSystem& system, int port, double timeout_s) {
  system.start("roscore", {"roscore", "-p", std::to_string(port)});
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < until) {
    if (accepts(port)) return true;
    if (system.wait_exit("roscore", 0.05)) break;
  }
  ADD_FAILURE() << "roscore did not answer on port " << port << " in " << timeout_s << " s:\n" << system.output("roscore");
  return false;
}

}  // namespace kestrel::test
