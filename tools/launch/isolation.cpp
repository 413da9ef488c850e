#include "tools/launch/isolation.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <net/if.h>
#include <net/route.h>
#include <netinet/in.h>
#include <sched.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace kestrel::launch {
namespace {

std::string errno_text() { return std::strerror(errno); }

void write_proc_file(const char* path, const std::string& text) {
  // in-place: the kernel's /proc/self files, not data
  const int fd = ::open(path, O_WRONLY | O_CLOEXEC);
  const bool ok = fd >= 0 && ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  const std::string why = errno_text();
  if (fd >= 0) ::close(fd);
  if (!ok) throw IsolationError(std::string("cannot write ") + path + ": " + why);
}

// Maps our own uid and gid into the new user namespace, so that files keep their owner and
// the command runs as the same user; the namespace still grants CAP_NET_ADMIN over the new
// network namespace, which is all configure_loopback() needs.
void map_own_ids(uid_t uid, gid_t gid) {
  write_proc_file("/proc/self/setgroups", "deny");  // required before gid_map without privilege
  write_proc_file("/proc/self/uid_map", std::to_string(uid) + " " + std::to_string(uid) + " 1");
  write_proc_file("/proc/self/gid_map", std::to_string(gid) + " " + std::to_string(gid) + " 1");
}

void set_ipv4(sockaddr* sa, uint32_t host_order_address) {
  auto* in = reinterpret_cast<sockaddr_in*>(sa);
  in->sin_family = AF_INET;
  in->sin_addr.s_addr = htonl(host_order_address);
}

// The equivalent of `ip link set lo up multicast on; ip route add 224.0.0.0/4 dev lo`, done
// with the classic ioctls so that it needs no external program.
void configure_loopback() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) throw IsolationError("cannot open a socket in the new namespace: " + errno_text());
  auto fail = [fd](const std::string& what) {
    const std::string why = errno_text();
    ::close(fd);
    throw IsolationError(what + ": " + why);
  };
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, "lo", IFNAMSIZ - 1);
  if (::ioctl(fd, SIOCGIFFLAGS, &ifr) != 0) fail("cannot read the flags of lo");
  ifr.ifr_flags = static_cast<short>(ifr.ifr_flags | IFF_UP | IFF_MULTICAST);
  if (::ioctl(fd, SIOCSIFFLAGS, &ifr) != 0) fail("cannot bring lo up with multicast");

  rtentry route{};
  set_ipv4(&route.rt_dst, 0xE0000000u);      // 224.0.0.0
  set_ipv4(&route.rt_genmask, 0xF0000000u);  // /4
  route.rt_flags = RTF_UP;
  char device[] = "lo";
  route.rt_dev = device;
  if (::ioctl(fd, SIOCADDRT, &route) != 0 && errno != EEXIST)
    fail("cannot add the route 224.0.0.0/4 dev lo");
  ::close(fd);
}

}  // namespace

IsolationMethod enter_private_network() {
  if (::unshare(CLONE_NEWNET) == 0) {
    configure_loopback();
    return IsolationMethod::kNetworkNamespace;
  }
  const std::string plain_error = errno_text();
  const uid_t uid = ::getuid();
  const gid_t gid = ::getgid();
  if (::unshare(CLONE_NEWUSER | CLONE_NEWNET) != 0) {
    throw IsolationError("cannot make a private network namespace: as this user (" +
                         plain_error + "), nor in a user namespace (" + errno_text() +
                         "); run as root or enable unprivileged user namespaces");
  }
  map_own_ids(uid, gid);
  configure_loopback();
  return IsolationMethod::kUserNetworkNamespace;
}

PrivateNetworkPair enter_private_network_pair() {
  PrivateNetworkPair pair;
  pair.method = enter_private_network();
  pair.onboard_fd = ::open("/proc/self/ns/net", O_RDONLY | O_CLOEXEC);
  if (pair.onboard_fd < 0) throw IsolationError("cannot open /proc/self/ns/net: " + errno_text());
  // Inside the first namespace (and its user namespace, if one was needed) we may make more.
  if (::unshare(CLONE_NEWNET) != 0) {
    const std::string why = errno_text();
    ::close(pair.onboard_fd);
    throw IsolationError("cannot make the second private network namespace: " + why);
  }
  configure_loopback();
  pair.offboard_fd = ::open("/proc/self/ns/net", O_RDONLY | O_CLOEXEC);
  if (pair.offboard_fd < 0) {
    const std::string why = errno_text();
    ::close(pair.onboard_fd);
    throw IsolationError("cannot open /proc/self/ns/net: " + why);
  }
  return pair;
}

std::string to_string(IsolationMethod method) {
  return method == IsolationMethod::kNetworkNamespace ? "network namespace"
                                                      : "user + network namespace";
}

}  // namespace kestrel::launch
