#pragma once
// A built-in Stata-like floor for the planning experiments (the paper's §4 simulation: a
// 13 x 23 m ground floor): a central corridor with rooms on both sides joined by 2.4 m doors,
// walls 3 m high, at 0.1 m resolution. Deterministic; needs no data files.
//
// The five start/goal pairs of the experiments are at least 8.53 m apart, like the paper's.

#include <array>
#include <utility>

#include "planner/grid_environment.h"

namespace kestrel::planner {

OccupancyGrid stata_like_floor();

/// (start, goal) pairs in the floor's free space, at flight height 1 m.
std::array<std::pair<Config, Config>, 5> stata_like_pairs();

}  // namespace kestrel::planner
