#pragma once
// The samplers by the names the tools, the experiments and the planner process take them
// (`--sampler`): one place that says which sampler a name means and with which settings.

#include <memory>
#include <string>
#include <vector>

#include "planner/sampler.h"
#include "planner/sensor_model.h"

namespace kestrel::planner {

/// uniform, su, gaussian, bridge, su-ukf: the order the paper's tables list them.
const std::vector<std::string>& sampler_names();

/// The sampler called `name` over `space`. The sensor-uncertainty samplers weigh a
/// configuration by what `sensor` would see there: su by tr(information) (§3.2.1, kept when it
/// passes the running threshold), su-ukf by the UKF's information gain against `ukf_prior`
/// (Algorithm 2, then kept with probability equal to its weight). Gaussian and bridge sample
/// at the sensor's range (twice it for the bridge). `space` and `sensor` must outlive the
/// sampler. Throws std::invalid_argument for an unknown name.
std::unique_ptr<Sampler> make_sampler(const std::string& name, const ConfigurationSpace& space,
                                      const FeatureSensor& sensor, const Mat4& ukf_prior);

}  // namespace kestrel::planner
