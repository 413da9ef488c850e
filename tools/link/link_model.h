#pragma once
// One direction of an emulated network link (the Wi-Fi between the vehicle and the ground
// station): given each datagram's arrival time and size, decides whether it is dropped and,
// if not, when it comes out at the far end. No sockets, no clock: kestrel-link feeds it the
// real datagrams with the wall clock, the tests feed it numbers.
//
// The model, per datagram of `bytes` arriving at time t (seconds, non-decreasing):
//  1. Queue: the datagram waits behind those sent before it in a FIFO drained at `rate_bps`
//     (bits per second, the datagram's `bytes` * 8 bits, no framing overhead). If the bytes
//     still waiting (the backlog at t) plus its own exceed `queue_bytes`, it is dropped at
//     once (drop-tail, as a full interface queue does) and takes no link time.
//  2. Air: it is on the link from max(t, the end of the previous one) for bytes*8/rate_bps.
//  3. Loss: with probability `loss` it is lost in the air; it has still used its link time
//     (a lost radio frame costs airtime).
//  4. Propagation: it comes out delay_s + u*jitter_s after leaving the queue, u uniform in
//     [-1, 1], but never before the datagram delivered before it (one link keeps order:
//     LCM's fragments of a message arrive in order, as over a single Wi-Fi hop).
//
// Invariants: a datagram is delivered at or after arrival + its transmission time + delay_s -
// jitter_s; deliveries are in arrival order; the backlog never exceeds queue_bytes; the same
// parameters, seed and arrivals give the same verdicts on every platform (mt19937_64, whose
// output the C++ standard fixes, turned into [0, 1) by hand).

#include <cstdint>
#include <random>
#include <string>

namespace kestrel::link {

struct LinkParams {
  double delay_s = 0.030;    ///< mean one-way delay after the queue, s (>= 0)
  double jitter_s = 0.010;   ///< the delay varies uniformly by up to this much either way, s (<= delay_s)
  double loss = 0.0;         ///< probability that a datagram is lost, 0..1
  double rate_bps = 20e6;    ///< link rate, bits per second (> 0)
  int64_t queue_bytes = 262144;  ///< the queue holds at most this many bytes (> 0)
  uint64_t seed = 1;         ///< the loss and jitter draws
};

/// Empty if `p` is usable, else what is wrong with it (one line).
std::string check(const LinkParams& p);

struct Verdict {
  enum Fate { kDelivered, kLost, kQueueFull };
  Fate fate = kDelivered;
  double deliver_at = 0.0;  ///< kDelivered: when it comes out at the far end, s
};

struct LinkStats {
  int64_t offered = 0, delivered = 0, lost = 0, queue_full = 0;
  int64_t bytes_offered = 0, bytes_delivered = 0;
  double max_backlog_bytes = 0.0;  ///< the largest backlog a datagram found on arrival
};

class LinkModel {
 public:
  /// Throws std::invalid_argument with check()'s text when `params` is unusable.
  explicit LinkModel(const LinkParams& params);

  /// The fate of a datagram of `bytes` arriving at `t` (s; earlier than the previous
  /// arrival is taken as equal to it).
  Verdict offer(double t, int64_t bytes);

  /// Bytes still waiting or on the link at `t` (not counting propagation).
  double backlog_bytes(double t) const;

  const LinkStats& stats() const { return stats_; }
  const LinkParams& params() const { return params_; }

 private:
  double uniform01();  ///< [0, 1), 53 bits of one mt19937_64 draw

  LinkParams params_;
  std::mt19937_64 rng_;
  double last_arrival_ = 0.0;
  double busy_until_ = 0.0;        ///< when the link finishes sending what it has
  double last_delivery_ = 0.0;     ///< the latest delivery time handed out
  LinkStats stats_;
};

}  // namespace kestrel::link
