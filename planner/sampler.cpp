// The four samplers and the running-normal threshold of Algorithm 2.
#include "planner/sampler.h"

#include "common/numbers.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kestrel::planner {

bool RunningThreshold::accept(double w, Rng& rng) {
  bool ok = true;
  if (count_ >= 2) {
    // mean + sd * z is how libstdc++ draws N(mean, sd), so the stream is unchanged; written out
    // because sd may be 0 (every weight so far equal, e.g. no feature seen anywhere), which
    // std::normal_distribution does not allow. Then nothing tells the candidates apart and a
    // weight equal to the rest is accepted: the sampler falls back to uniform.
    std::normal_distribution<double> z(0.0, 1.0);
    const double sd = std::sqrt(variance());
    const double threshold = mean_ + sd * z(rng);
    ok = w > threshold || (sd == 0.0 && w >= mean_);
  }
  ++count_;
  const double delta = w - mean_;
  mean_ += delta / static_cast<double>(count_);
  m2_ += delta * (w - mean_);
  return ok;
}

namespace {

Config offset(const ConfigurationSpace& space, const Config& q, double sigma, Rng& rng) {
  std::normal_distribution<double> n(0.0, sigma);
  Config out = q;
  for (int i = 0; i < 3; ++i) out[i] += n(rng);
  std::uniform_real_distribution<double> yaw(-kPi, kPi);
  out[3] = yaw(rng);
  return space.clamp_band(out);
}

class UniformSampler : public Sampler {
 public:
  UniformSampler(const ConfigurationSpace& s, int max_attempts) : space_(s), max_(max_attempts) {}
  std::string name() const override { return "uniform"; }
  std::optional<Config> sample(Rng& rng, SampleTrace* trace) override {
    for (int i = 1; i <= max_; ++i) {
      const Config q = space_.uniform(rng);
      if (space_.is_valid(q)) {
        if (trace) trace->attempts = i;
        return q;
      }
    }
    if (trace) trace->attempts = max_;
    return std::nullopt;
  }

 private:
  const ConfigurationSpace& space_;
  int max_;
};

class GaussianSampler : public Sampler {
 public:
  GaussianSampler(const ConfigurationSpace& s, double sigma, int max_attempts)
      : space_(s), sigma_(sigma), max_(max_attempts) {
    if (!(sigma > 0.0)) throw std::invalid_argument("gaussian sampler: sigma must be > 0");
  }
  std::string name() const override { return "gaussian"; }
  std::optional<Config> sample(Rng& rng, SampleTrace* trace) override {
    for (int i = 1; i <= max_; ++i) {
      const Config q1 = space_.uniform(rng);
      const Config q2 = offset(space_, q1, sigma_, rng);
      const bool v1 = space_.is_valid(q1), v2 = space_.is_valid(q2);
      if (v1 == v2) continue;
      if (trace) {
        trace->attempts = i;
        trace->witnesses = {v1 ? q2 : q1};
      }
      return v1 ? q1 : q2;
    }
    if (trace) trace->attempts = max_;
    return std::nullopt;
  }

 private:
  const ConfigurationSpace& space_;
  double sigma_;
  int max_;
};

class BridgeSampler : public Sampler {
 public:
  BridgeSampler(const ConfigurationSpace& s, double sigma, int max_attempts)
      : space_(s), sigma_(sigma), max_(max_attempts) {
    if (!(sigma > 0.0)) throw std::invalid_argument("bridge sampler: sigma must be > 0");
  }
  std::string name() const override { return "bridge"; }
  std::optional<Config> sample(Rng& rng, SampleTrace* trace) override {
    std::uniform_real_distribution<double> yaw(-kPi, kPi);
    for (int i = 1; i <= max_; ++i) {
      const Config q1 = space_.uniform(rng);
      if (space_.is_valid(q1)) continue;
      const Config q2 = offset(space_, q1, sigma_, rng);
      if (space_.is_valid(q2)) continue;
      Config mid = 0.5 * (q1 + q2);
      mid[3] = yaw(rng);
      if (!space_.is_valid(mid)) continue;
      if (trace) {
        trace->attempts = i;
        trace->witnesses = {q1, q2};
      }
      return mid;
    }
    if (trace) trace->attempts = max_;
    return std::nullopt;
  }

 private:
  const ConfigurationSpace& space_;
  double sigma_;
  int max_;
};

class SensorSampler : public Sampler {
 public:
  SensorSampler(const ConfigurationSpace& s, std::function<double(const Config&)> weight, std::string name,
                int max_attempts, SuAcceptance acceptance)
      : space_(s), weight_(std::move(weight)), name_(std::move(name)), max_(max_attempts), acceptance_(acceptance) {}
  std::string name() const override { return name_; }
  std::optional<Config> sample(Rng& rng, SampleTrace* trace) override {
    for (int i = 1; i <= max_; ++i) {
      const Config q = space_.uniform(rng);
      if (!space_.is_valid(q)) continue;
      const double w = std::max(0.0, weight_(q));
      max_weight_ = std::max(max_weight_, w);
      const double normalised = max_weight_ > 0.0 ? w / max_weight_ : 0.0;
      if (!threshold_.accept(normalised, rng)) continue;
      // Algorithm 2, line 12: a sample past the threshold is added with probability equal to
      // its normalised weight. While every weight so far is 0 nothing tells candidates apart
      // and it is added (as the threshold does then).
      if (acceptance_ == SuAcceptance::kThresholdThenWeight && max_weight_ > 0.0 && !(unit_(rng) < normalised))
        continue;
      if (trace) {
        trace->attempts = i;
        trace->weight = normalised;
      }
      return q;
    }
    if (trace) trace->attempts = max_;
    return std::nullopt;
  }

 private:
  const ConfigurationSpace& space_;
  std::function<double(const Config&)> weight_;
  std::string name_;
  int max_;
  SuAcceptance acceptance_;
  double max_weight_ = 0.0;
  RunningThreshold threshold_;
  std::uniform_real_distribution<double> unit_{0.0, 1.0};
};

}  // namespace

std::unique_ptr<Sampler> make_uniform_sampler(const ConfigurationSpace& space, int max_attempts) {
  return std::make_unique<UniformSampler>(space, max_attempts);
}
std::unique_ptr<Sampler> make_gaussian_sampler(const ConfigurationSpace& space, double sigma_m, int max_attempts) {
  return std::make_unique<GaussianSampler>(space, sigma_m, max_attempts);
}
std::unique_ptr<Sampler> make_bridge_sampler(const ConfigurationSpace& space, double sigma_m, int max_attempts) {
  return std::make_unique<BridgeSampler>(space, sigma_m, max_attempts);
}
std::unique_ptr<Sampler> make_sensor_sampler(const ConfigurationSpace& space,
                                             std::function<double(const Config&)> weight, std::string name,
                                             int max_attempts, SuAcceptance acceptance) {
  return std::make_unique<SensorSampler>(space, std::move(weight), std::move(name), max_attempts, acceptance);
}

}  // namespace kestrel::planner
