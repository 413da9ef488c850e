#pragma once
// VoOptions by name, for command lines and configuration files: `set_option(o, "fast.threshold",
// "15")`. Names are the struct paths of options.h (section.field); enums take the names
// to_string() gives them.
//
// Invariant: every field of VoOptions has exactly one key; a bad key or value throws
// std::invalid_argument naming it, and leaves the options unchanged.

#include <string>
#include <vector>

#include "vo/options.h"

namespace kestrel::vo {

/// Sets the field called `key` from `value`.
void set_option(VoOptions& options, const std::string& key, const std::string& value);

/// Sets a field from "KEY=VALUE" (a --set argument); throws std::invalid_argument when the
/// text has no '=' or set_option refuses it.
void set_option_assignment(VoOptions& options, const std::string& key_equals_value);

/// "key = value" for every field, in declaration order (for --print-config and READMEs).
std::vector<std::string> describe_options(const VoOptions& options);

}  // namespace kestrel::vo
