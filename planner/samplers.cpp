#include "planner/samplers.h"

#include <stdexcept>

namespace kestrel::planner {

const std::vector<std::string>& sampler_names() {
  static const std::vector<std::string> names = {"uniform", "su", "gaussian", "bridge", "su-ukf"};
  return names;
}

std::unique_ptr<Sampler> make_sampler(const std::string& name, const ConfigurationSpace& space,
                                      const FeatureSensor& sensor, const Mat4& ukf_prior) {
  const double range = sensor.options().max_range_m;
  if (name == "uniform") return make_uniform_sampler(space);
  if (name == "gaussian") return make_gaussian_sampler(space, range);
  if (name == "bridge") return make_bridge_sampler(space, 2.0 * range);
  // Each as the paper states it: the EKF sampler keeps what passes the threshold (§3.2.1),
  // Algorithm 2 (the UKF sampler) then adds it with probability = its normalised weight.
  if (name == "su")
    return make_sensor_sampler(space, [&sensor](const Config& q) { return sensor.information(q).trace(); }, "su");
  if (name == "su-ukf")
    return make_sensor_sampler(
        space, [&sensor, ukf_prior](const Config& q) { return sensor.ukf_information_gain(q, ukf_prior); }, "su-ukf",
        100000, SuAcceptance::kThresholdThenWeight);
  std::string known;
  for (const std::string& n : sampler_names()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown sampler '" + name + "' (" + known + ")");
}

}  // namespace kestrel::planner
