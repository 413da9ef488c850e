#pragma once
// A number for a JSON report: null where it is not finite (JSON has no NaN or infinity, and a
// reader must see "not measured", not a made-up value).

#include <cmath>
#include <nlohmann/json.hpp>

namespace kestrel {

inline nlohmann::json finite_or_null(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

}  // namespace kestrel
