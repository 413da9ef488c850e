// kestrel-link: joins the onboard and the offboard network namespaces through an emulated
// Wi-Fi link. It holds a UDP socket on LCM's multicast group in each namespace, and carries
// the datagrams of the channels allowed in each direction (--up, --down) to the other side
// through the link model (tools/link/link_model.h): delay and jitter, loss, rate and a
// drop-tail queue, one model per direction, per datagram. The kernel here has neither veth
// nor netem, so this process stands in for both (tools/link/README.md).

#include <arpa/inet.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <netinet/in.h>
#include <poll.h>
#include <sched.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <chrono>
#include <cstring>
#include <deque>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/error.h"
#include "common/interrupt.h"
#include "common/transport/lcm_url.h"
#include "tools/link/lcm_datagram.h"
#include "tools/link/link_model.h"

namespace {

using kestrel::UnavailableError;
using namespace kestrel::link;

struct Options {
  std::string lcm_url;
  std::string onboard_netns, offboard_netns;
  std::vector<std::string> up = {"CAMERA_RGBD_Z>CAMERA_RGBD", "VO_UPDATE", "STATE"};
  std::vector<std::string> down = {"SLAM_CORRECTION", "PLAN"};
  double delay_ms = 30, jitter_ms = 10, loss_percent = 0, rate_mbit = 20, queue_kb = 256;
  uint64_t seed = 1;
  double duration_s = 0;
  std::string stats;
};

// IPv4 and UDP headers, counted on the link with each datagram's payload.
constexpr int64_t kHeaderBytes = 28;
// Send sockets per side: each sender on one side gets one of its own on the other, so that
// LCM's receivers (which put fragments together per sender address) never see two senders'
// fragments from one address.
constexpr size_t kSendSockets = 32;

std::string errno_text() { return std::strerror(errno); }

// The multicast group and port of a udpm:// URL.
sockaddr_in group_of(const std::string& url) {
  const std::string prefix = "udpm://";
  if (url.compare(0, prefix.size(), prefix) != 0)
    throw CLI::ValidationError("--lcm-url", "kestrel-link carries udpm:// only, not " + url);
  const std::string rest = url.substr(prefix.size(), url.find('?') - prefix.size());
  const size_t colon = rest.find(':');
  sockaddr_in a{};
  a.sin_family = AF_INET;
  int port = 7667;
  try {
    if (colon != std::string::npos) port = std::stoi(rest.substr(colon + 1));
  } catch (const std::exception&) {
    port = -1;
  }
  if (port <= 0 || port > 65535 || ::inet_pton(AF_INET, rest.substr(0, colon).c_str(), &a.sin_addr) != 1)
    throw CLI::ValidationError("--lcm-url", "no multicast address and port in " + url);
  a.sin_port = htons(static_cast<uint16_t>(port));
  return a;
}

int open_netns(const std::string& path) {
  if (path.empty()) return -1;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw UnavailableError("cannot open the network namespace " + path + ": " + errno_text());
  return fd;
}

void enter(int netns_fd, int home_fd, const std::string& what) {
  const int fd = netns_fd >= 0 ? netns_fd : home_fd;
  if (::setns(fd, CLONE_NEWNET) != 0) throw UnavailableError("cannot enter the " + what + " network namespace: " + errno_text());
}

ino_t inode_of(int fd) {
  struct stat st {};
  return ::fstat(fd, &st) == 0 ? st.st_ino : 0;
}

// One namespace: a socket that hears the group, and sockets to send into it.
struct Side {
  std::string name;
  int recv_fd = -1;
  std::vector<int> send_fds;
  std::set<uint16_t> own_ports;          ///< the send sockets' ports: what we sent ourselves
  std::map<uint64_t, size_t> sender_of;  ///< a far sender -> our send socket for it
  std::vector<uint64_t> last_use;        ///< per send socket
  int64_t echoes = 0;
};

void open_side(Side& side, const sockaddr_in& group) {
  side.recv_fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (side.recv_fd < 0) throw UnavailableError(side.name + ": cannot open a socket: " + errno_text());
  const int one = 1;
  ::setsockopt(side.recv_fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  const int buffer = 8 << 20;
  if (::setsockopt(side.recv_fd, SOL_SOCKET, SO_RCVBUFFORCE, &buffer, sizeof buffer) != 0)
    ::setsockopt(side.recv_fd, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof buffer);
  sockaddr_in any{};
  any.sin_family = AF_INET;
  any.sin_port = group.sin_port;
  any.sin_addr.s_addr = htonl(INADDR_ANY);
  if (::bind(side.recv_fd, reinterpret_cast<const sockaddr*>(&any), sizeof any) != 0)
    throw UnavailableError(side.name + ": cannot bind port " + std::to_string(ntohs(group.sin_port)) + ": " + errno_text());
  ip_mreq mreq{};
  mreq.imr_multiaddr = group.sin_addr;
  mreq.imr_interface.s_addr = htonl(INADDR_ANY);
  if (::setsockopt(side.recv_fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mreq, sizeof mreq) != 0)
    throw UnavailableError(side.name + ": cannot join the LCM group (no multicast route?): " + errno_text());
  for (size_t i = 0; i < kSendSockets; ++i) {
    const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0) throw UnavailableError(side.name + ": cannot open a socket: " + errno_text());
    const unsigned char ttl = 0;  // as LCM's ttl=0: the host only
    ::setsockopt(fd, IPPROTO_IP, IP_MULTICAST_TTL, &ttl, sizeof ttl);
    sockaddr_in local{};
    local.sin_family = AF_INET;
    local.sin_addr.s_addr = htonl(INADDR_ANY);
    socklen_t len = sizeof local;
    if (::bind(fd, reinterpret_cast<const sockaddr*>(&local), sizeof local) != 0 ||
        ::getsockname(fd, reinterpret_cast<sockaddr*>(&local), &len) != 0)
      throw UnavailableError(side.name + ": cannot bind a send socket: " + errno_text());
    side.send_fds.push_back(fd);
    side.own_ports.insert(ntohs(local.sin_port));
  }
  side.last_use.assign(kSendSockets, 0);
}

// The send socket on `side` for a sender of the other side: its own, or the one used least
// recently.
int send_fd_for(Side& side, uint64_t sender, uint64_t tick) {
  auto it = side.sender_of.find(sender);
  if (it == side.sender_of.end()) {
    size_t pick = 0;
    for (size_t i = 1; i < side.last_use.size(); ++i)
      if (side.last_use[i] < side.last_use[pick]) pick = i;
    for (auto s = side.sender_of.begin(); s != side.sender_of.end();)
      s = s->second == pick ? side.sender_of.erase(s) : std::next(s);
    it = side.sender_of.emplace(sender, pick).first;
  }
  side.last_use[it->second] = tick;
  return side.send_fds[it->second];
}

struct InTransit {
  double deliver_at;
  uint64_t sender;
  std::vector<uint8_t> bytes;
};

// One direction: from one side's group to the other's.
struct Direction {
  std::string name;  ///< "up" or "down"
  Side* from;
  Side* to;
  Router router;
  LinkModel model;
  std::deque<InTransit> in_transit;
  int64_t send_errors = 0;
};

void write_stats(const std::string& path, const std::vector<Direction*>& directions, double seconds) {
  kestrel::AtomicFile file(path);  // a link killed while writing leaves no cut file that looks whole
  std::ostream& out = file.stream();
  out << "{\n  \"seconds\": " << fmt::format("{:.3f}", seconds) << ",\n";
  for (size_t i = 0; i < directions.size(); ++i) {
    const Direction& d = *directions[i];
    const LinkStats& s = d.model.stats();
    out << "  \"" << d.name << "\": {\"offered\": " << s.offered << ", \"delivered\": " << s.delivered
        << ", \"lost\": " << s.lost << ", \"queue_full\": " << s.queue_full << ", \"bytes_offered\": "
        << s.bytes_offered << ", \"bytes_delivered\": " << s.bytes_delivered
        << fmt::format(", \"max_backlog_bytes\": {:.0f}", s.max_backlog_bytes) << ", \"channels\": {";
    bool first = true;
    for (const auto& [channel, n] : d.router.forwarded()) {
      out << (first ? "" : ", ") << "\"" << channel << "\": {\"datagrams\": " << n
          << ", \"bytes\": " << d.router.forwarded_bytes().at(channel) << "}";
      first = false;
    }
    out << "}}" << (i + 1 < directions.size() ? "," : "") << "\n";
  }
  out << "}\n";
  file.commit();
}

int run(const Options& o) {
  const sockaddr_in group = group_of(kestrel::transport::resolve_lcm_url(o.lcm_url));
  auto params = [&](uint64_t seed) {
    LinkParams p;
    p.delay_s = o.delay_ms * 1e-3;
    p.jitter_s = o.jitter_ms * 1e-3;
    p.loss = o.loss_percent * 1e-2;
    p.rate_bps = o.rate_mbit * 1e6;
    p.queue_bytes = static_cast<int64_t>(o.queue_kb * 1024);
    p.seed = seed;
    if (const std::string why = check(p); !why.empty()) throw CLI::ValidationError("link", why);
    return p;
  };
  Direction up{"up", nullptr, nullptr, Router(o.up), LinkModel(params(o.seed)), {}, 0};
  Direction down{"down", nullptr, nullptr, Router(o.down), LinkModel(params(o.seed + 1)), {}, 0};

  const int home = ::open("/proc/self/ns/net", O_RDONLY | O_CLOEXEC);
  if (home < 0) throw UnavailableError("cannot open /proc/self/ns/net: " + errno_text());
  const int onboard_ns = open_netns(o.onboard_netns);
  const int offboard_ns = open_netns(o.offboard_netns);
  if (inode_of(onboard_ns >= 0 ? onboard_ns : home) == inode_of(offboard_ns >= 0 ? offboard_ns : home))
    throw CLI::ValidationError("--onboard-netns/--offboard-netns",
                               "both sides are one network namespace: give the other one");
  Side onboard{"onboard", -1, {}, {}, {}, {}, 0};
  Side offboard{"offboard", -1, {}, {}, {}, {}, 0};
  enter(onboard_ns, home, "onboard");
  open_side(onboard, group);
  enter(offboard_ns, home, "offboard");
  open_side(offboard, group);
  enter(-1, home, "own");  // back where we started; the sockets keep their namespaces
  up.from = &onboard;
  up.to = &offboard;
  down.from = &offboard;
  down.to = &onboard;
  spdlog::info("link {}:{}: {:.0f} ± {:.0f} ms, {:.1f} % loss, {:.1f} Mbit/s, queue {:.0f} kB, seed {}",
               ::inet_ntoa(group.sin_addr), ntohs(group.sin_port), o.delay_ms, o.jitter_ms, o.loss_percent,
               o.rate_mbit, o.queue_kb, o.seed);
  spdlog::info("up: {}; down: {}", fmt::join(o.up, ", "), fmt::join(o.down, ", "));

  const auto& interrupted = kestrel::catch_interrupts();
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto now_s = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  std::vector<uint8_t> buffer(70000);
  uint64_t tick = 0;
  Direction* directions[] = {&up, &down};

  auto receive = [&](Direction& d) {
    for (;;) {
      sockaddr_in from{};
      socklen_t len = sizeof from;
      const ssize_t n = ::recvfrom(d.from->recv_fd, buffer.data(), buffer.size(), 0,
                                   reinterpret_cast<sockaddr*>(&from), &len);
      if (n < 0) {
        if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)
          spdlog::warn("{}: receive failed: {}", d.from->name, errno_text());
        return;
      }
      if (d.from->own_ports.count(ntohs(from.sin_port))) {  // what we sent, back by loopback
        ++d.from->echoes;
        continue;
      }
      const uint64_t sender = (uint64_t{ntohl(from.sin_addr.s_addr)} << 16) | ntohs(from.sin_port);
      auto out = d.router.route(sender, buffer.data(), static_cast<size_t>(n));
      if (!out) continue;
      const Verdict v = d.model.offer(now_s(), static_cast<int64_t>(out->size()) + kHeaderBytes);
      if (v.fate == Verdict::kDelivered) d.in_transit.push_back({v.deliver_at, sender, std::move(*out)});
    }
  };
  auto deliver = [&](Direction& d, double now) {
    while (!d.in_transit.empty() && d.in_transit.front().deliver_at <= now) {
      InTransit& m = d.in_transit.front();
      const int fd = send_fd_for(*d.to, m.sender, ++tick);
      if (::sendto(fd, m.bytes.data(), m.bytes.size(), 0, reinterpret_cast<const sockaddr*>(&group),
                   sizeof group) < 0)
        ++d.send_errors;
      d.in_transit.pop_front();
    }
  };

  while (!interrupted && (o.duration_s <= 0 || now_s() < o.duration_s)) {
    double next = now_s() + 0.1;
    for (Direction* d : directions)
      if (!d->in_transit.empty()) next = std::min(next, d->in_transit.front().deliver_at);
    const double wait = std::max(0.0, next - now_s());
    timespec timeout{static_cast<time_t>(wait), static_cast<long>((wait - static_cast<double>(static_cast<time_t>(wait))) * 1e9)};
    pollfd fds[] = {{onboard.recv_fd, POLLIN, 0}, {offboard.recv_fd, POLLIN, 0}};
    ::ppoll(fds, 2, &timeout, nullptr);
    if (fds[0].revents & POLLIN) receive(up);
    if (fds[1].revents & POLLIN) receive(down);
    const double now = now_s();
    for (Direction* d : directions) deliver(*d, now);
  }

  const double seconds = now_s();
  for (Direction* d : directions) {
    const LinkStats& s = d->model.stats();
    spdlog::info("{}: {} datagrams ({:.1f} MB, {:.2f} Mbit/s) offered, {} delivered, {} lost, {} dropped by the "
                 "full queue (largest backlog {:.0f} kB); {} send errors, {} malformed, {} orphan fragments",
                 d->name, s.offered, s.bytes_offered * 1e-6, s.bytes_offered * 8e-6 / std::max(seconds, 1e-9),
                 s.delivered, s.lost, s.queue_full, s.max_backlog_bytes / 1024, d->send_errors, d->router.malformed(),
                 d->router.orphan_fragments());
    for (const auto& [channel, n] : d->router.forwarded())
      spdlog::info("{}:   {}: {} datagrams, {:.1f} kB/s", d->name, channel, n,
                   d->router.forwarded_bytes().at(channel) * 1e-3 / std::max(seconds, 1e-9));
  }
  if (!o.stats.empty()) write_stats(o.stats, {&up, &down}, seconds);
  for (Side* s : {&onboard, &offboard}) {
    ::close(s->recv_fd);
    for (int fd : s->send_fds) ::close(fd);
  }
  for (int fd : {home, onboard_ns, offboard_ns})
    if (fd >= 0) ::close(fd);
  if (kestrel::interrupt_signal() == SIGINT) return kestrel::kExitInterrupted;
  return kestrel::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app(
      "link",
      "Joins the onboard and the offboard network namespaces through an emulated Wi-Fi link: "
      "carries the LCM datagrams of the channels allowed each way, with delay, jitter, loss, a "
      "rate limit and a drop-tail queue (per datagram, seeded). Exit: 0 stopped; 2 usage; 4 no "
      "namespace or socket; 130 Ctrl-C.");
  Options o;
  app.add_option("--lcm-url", o.lcm_url, "LCM URL of both sides (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--onboard-netns", o.onboard_netns,
                 "The onboard side's network namespace, e.g. /proc/PID/ns/net (default: this process's)");
  app.add_option("--offboard-netns", o.offboard_netns,
                 "The offboard side's network namespace (default: this process's)");
  app.add_option("--up", o.up, "Channels carried onboard -> offboard (NAME, or FROM>TO to rename)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--down", o.down, "Channels carried offboard -> onboard")->delimiter(',')->capture_default_str();
  app.add_option("--delay", o.delay_ms, "Mean one-way delay, ms")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--jitter", o.jitter_ms, "The delay varies uniformly by up to this either way, ms (<= --delay)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--loss", o.loss_percent, "Datagrams lost, %")->check(CLI::Range(0.0, 100.0))->capture_default_str();
  app.add_option("--rate", o.rate_mbit, "Link rate each way, Mbit/s")->check(kestrel::cli::Positive)->capture_default_str();
  app.add_option("--queue", o.queue_kb, "Queue before the link each way, kB (drop-tail)")
      ->check(kestrel::cli::Positive)
      ->capture_default_str();
  app.add_option("--seed", o.seed, "Seed of the loss and the jitter (the down direction uses seed + 1)")
      ->capture_default_str();
  app.add_option("--duration", o.duration_s, "Stop after this many seconds (0: on a signal)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--stats", o.stats, "Write the link's counts here at the end (JSON)");
  return app.run(argc, argv, [&] { return run(o); });
}
