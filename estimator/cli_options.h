#pragma once
// The estimator's options on a command line (and so in --config files, section-less keys =
// long option names): shared by the process kestrel-estimator and the offline kestrel-estimate,
// so that both run the filter with the same configuration from the same keys.

#include <CLI/CLI.hpp>

#include "estimator/options.h"

namespace kestrel::estimator {

/// Adds every option of `o` to `app`, each with its default shown in --help. Values are
/// checked by CLI11 (ranges, choices), so a bad value is a usage error naming the option.
void add_estimator_options(CLI::App& app, EstimatorOptions& o);

}  // namespace kestrel::estimator
