#include "tools/replay/latency.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace kestrel::replay {

void LatencyLedger::begin_event(const std::string& input, double t_s) {
  input_ = input;
  started_s_ = t_s;
  in_event_ = true;
  seen_.clear();
  last_s_.clear();
}

void LatencyLedger::acknowledge(const std::string& process, const std::string& handled, double t_s) {
  if (!in_event_) return;
  double& last = last_s_.emplace(process, t_s).first->second;
  last = std::max(last, t_s);
  if (!seen_.emplace(process, handled).second) return;  // not the first of this channel
  samples_ms_[{input_, process, handled}].add(1e3 * (t_s - started_s_));
}

void LatencyLedger::end_event() {
  if (!in_event_) return;
  for (const auto& [process, t_s] : last_s_) samples_ms_[{input_, process, kAll}].add(1e3 * (t_s - started_s_));
  in_event_ = false;
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  // Nearest rank: the smallest value with at least q of the samples at or below it.
  const double rank = std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size()));
  const size_t i = rank < 1.0 ? 0 : static_cast<size_t>(rank) - 1;
  return values[std::min(i, values.size() - 1)];
}

namespace {
constexpr double kSmallestMs = 1e-3;  // 1 us: the first bin holds everything below
constexpr double kBinRatio = 1.01;
const size_t kBins = static_cast<size_t>(std::ceil(std::log(1e6 / kSmallestMs) / std::log(kBinRatio))) + 1;
}  // namespace

size_t LatencySamples::bin_of(double ms) {
  if (!(ms > kSmallestMs)) return 0;
  return std::min(kBins - 1, static_cast<size_t>(std::log(ms / kSmallestMs) / std::log(kBinRatio)));
}

double LatencySamples::value_of(size_t bin) {
  return kSmallestMs * std::pow(kBinRatio, static_cast<double>(bin) + 0.5);
}

void LatencySamples::add(double ms) {
  max_ = count_ == 0 ? ms : std::max(max_, ms);
  ++count_;
  if (bins_.empty() && exact_.size() < kExactSamples) {
    exact_.push_back(ms);
    return;
  }
  if (bins_.empty()) {
    bins_.assign(kBins, 0);
    for (double x : exact_) ++bins_[bin_of(x)];
    exact_.clear();
    exact_.shrink_to_fit();
  }
  ++bins_[bin_of(ms)];
}

double LatencySamples::quantile(double q) const {
  if (bins_.empty()) return replay::quantile(exact_, q);
  const double rank = std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(count_));
  const int64_t wanted = std::max<int64_t>(1, static_cast<int64_t>(rank));
  int64_t seen = 0;
  for (size_t b = 0; b < bins_.size(); ++b) {
    seen += bins_[b];
    if (seen >= wanted) return std::min(value_of(b), max_);
  }
  return max_;
}

std::vector<LatencyRow> LatencyLedger::rows() const {
  std::vector<LatencyRow> out;
  for (const auto& [key, ms] : samples_ms_) {
    const auto& [input, process, handled] = key;
    out.push_back({input, process, handled, ms.count(), ms.quantile(0.5), ms.quantile(0.95), ms.max()});
  }
  std::stable_sort(out.begin(), out.end(), [](const LatencyRow& a, const LatencyRow& b) {
    return std::tie(a.input, a.median_ms) < std::tie(b.input, b.median_ms);
  });
  return out;
}

std::string format_latency(const std::vector<LatencyRow>& rows) {
  if (rows.empty()) return "";
  std::string s = "latency, from publishing an event to each acknowledgement (wall clock):\n";
  s += fmt::format("{:<16} {:<12} {:<16} {:>7} {:>9} {:>9} {:>9}\n", "input", "process",
                              "handled", "events", "median ms", "p95 ms", "max ms");
  for (const auto& r : rows)
    s += fmt::format("{:<16} {:<12} {:<16} {:>7} {:>9.2f} {:>9.2f} {:>9.2f}\n", r.input, r.process,
                     r.handled, r.count, r.median_ms, r.p95_ms, r.max_ms);
  return s;
}

}  // namespace kestrel::replay
