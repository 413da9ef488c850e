#pragma once
// Samplers behind one interface (as OMPL's valid-state samplers): each call returns one
// accepted configuration, or nothing after `max_attempts` candidates.
//
//  uniform   a uniform candidate, kept when valid
//  gaussian  (Boor et al.) a uniform q1 and q2 = q1 + N(0, sigma^2) in position; when exactly
//            one is valid, that one is kept (sigma = the sensor's range in the paper)
//  bridge    (Hsu et al.) q1 uniform, q2 = q1 + N(0, sigma^2); both invalid and their
//            midpoint valid -> the midpoint (sigma = 2 x sensor range)
//  sensor    (the paper's §3.2.1 and Algorithm 2) a valid uniform candidate with weight w
//            (EKF tr(M) or UKF information gain), normalised by the largest weight seen so far,
//            passes when it exceeds a threshold drawn from N(mean, var) of the normalised
//            weights seen; the EKF paragraph then keeps it, Algorithm 2 (the UKF sampler) adds
//            it with probability w (line 12; always while every weight so far is 0)
// The trace (optional) records the attempts and the witnesses that justified the sample, so
// tests can check each sampler against its definition.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "planner/configuration_space.h"

namespace kestrel::planner {

struct SampleTrace {
  int attempts = 0;
  std::vector<Config> witnesses;  ///< gaussian: the invalid partner; bridge: both ends
  double weight = 0.0;            ///< sensor: normalised weight of the accepted sample
};

class Sampler {
 public:
  virtual ~Sampler() = default;
  virtual std::string name() const = 0;
  virtual std::optional<Config> sample(Rng& rng, SampleTrace* trace = nullptr) = 0;
};

/// The running-normal acceptance test of Algorithm 2, on weights already in [0, 1].
class RunningThreshold {
 public:
  /// Records w and returns whether it beats a threshold drawn from N(mean, var) of the weights
  /// recorded before it (the first two are always accepted; while every weight so far is the
  /// same, one no smaller is accepted).
  bool accept(double w, Rng& rng);
  double mean() const { return mean_; }
  double variance() const { return count_ > 1 ? m2_ / (count_ - 1) : 0.0; }
  long count() const { return count_; }

 private:
  long count_ = 0;
  double mean_ = 0.0, m2_ = 0.0;  // Welford
};

std::unique_ptr<Sampler> make_uniform_sampler(const ConfigurationSpace& space, int max_attempts = 10000);
std::unique_ptr<Sampler> make_gaussian_sampler(const ConfigurationSpace& space, double sigma_m,
                                               int max_attempts = 100000);
std::unique_ptr<Sampler> make_bridge_sampler(const ConfigurationSpace& space, double sigma_m,
                                             int max_attempts = 1000000);
/// How a sensor-uncertainty candidate that passed the threshold is kept.
enum class SuAcceptance {
  kThreshold,             ///< kept (§3.2.1, the EKF sampler: "retain the sample if tr(M_k) > P_k")
  kThresholdThenWeight,   ///< kept with probability = its normalised weight (Algorithm 2, line 12)
};

/// `weight` maps a valid configuration to its information (>= 0).
std::unique_ptr<Sampler> make_sensor_sampler(const ConfigurationSpace& space,
                                             std::function<double(const Config&)> weight,
                                             std::string name = "sensor", int max_attempts = 100000,
                                             SuAcceptance acceptance = SuAcceptance::kThreshold);

}  // namespace kestrel::planner
