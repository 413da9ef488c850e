#include "tools/link/link_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kestrel::link {

std::string check(const LinkParams& p) {
  if (!std::isfinite(p.delay_s) || p.delay_s < 0) return "the delay must be finite and >= 0";
  if (!std::isfinite(p.jitter_s) || p.jitter_s < 0 || p.jitter_s > p.delay_s)
    return "the jitter must be >= 0 and at most the delay";
  if (!(p.loss >= 0 && p.loss <= 1)) return "the loss must be within 0..1";
  if (!std::isfinite(p.rate_bps) || p.rate_bps <= 0) return "the rate must be finite and > 0";
  if (p.queue_bytes <= 0) return "the queue must hold at least one byte";
  return {};
}

LinkModel::LinkModel(const LinkParams& params) : params_(params), rng_(params.seed) {
  if (const std::string why = check(params); !why.empty()) throw std::invalid_argument(why);
}

double LinkModel::uniform01() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }

double LinkModel::backlog_bytes(double t) const {
  return std::max(0.0, busy_until_ - t) * params_.rate_bps / 8.0;
}

Verdict LinkModel::offer(double t, int64_t bytes) {
  t = std::max(t, last_arrival_);
  last_arrival_ = t;
  ++stats_.offered;
  stats_.bytes_offered += bytes;
  const double backlog = backlog_bytes(t);
  stats_.max_backlog_bytes = std::max(stats_.max_backlog_bytes, backlog);
  Verdict v;
  if (backlog + static_cast<double>(bytes) > static_cast<double>(params_.queue_bytes)) {
    ++stats_.queue_full;
    v.fate = Verdict::kQueueFull;
    return v;
  }
  const double sent = std::max(t, busy_until_) + static_cast<double>(bytes) * 8.0 / params_.rate_bps;
  busy_until_ = sent;
  // Both draws for every datagram on the link, so that the loss does not shift the jitter's
  // sequence (a sweep over the loss keeps the same delays).
  const double lose = uniform01();
  const double u = 2.0 * uniform01() - 1.0;
  if (lose < params_.loss) {
    ++stats_.lost;
    v.fate = Verdict::kLost;
    return v;
  }
  v.deliver_at = std::max(sent + params_.delay_s + u * params_.jitter_s, last_delivery_);
  last_delivery_ = v.deliver_at;
  ++stats_.delivered;
  stats_.bytes_delivered += bytes;
  return v;
}

}  // namespace kestrel::link
