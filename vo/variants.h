#pragma once
// The paper's Table 1 variants (and kestrel's own default) as named option sets: each changes
// one stage of VoOptions{} so that an ablation isolates that stage's effect.
//
// Invariant: every variant's options pass VoOptions::validate(); names are unique, lower-case
// and usable on a command line (`kestrel vo --variant NAME`).

#include <string>
#include <vector>

#include "vo/options.h"

namespace kestrel::vo {

struct Variant {
  std::string name;         ///< e.g. "ransac"
  std::string description;  ///< the row label of the paper's Table 1
  VoOptions options;
};

/// All variants, "default" first, in the order of the paper's Table 1.
const std::vector<Variant>& variants();

/// The variant called `name`; throws std::invalid_argument listing the known names.
const Variant& variant(const std::string& name);

}  // namespace kestrel::vo
