#pragma once
// The targets of each kind of input, gathered by targets() (registry.cpp).

#include <vector>

#include "fuzz/target.h"

namespace kestrel::fuzz {

std::vector<Target> message_targets();  ///< messages off the bus, LCM logs (message_targets.cpp)
std::vector<Target> text_targets();     ///< TUM lists, trajectories, g2o, worlds, INI (text_targets.cpp)
std::vector<Target> image_targets();    ///< PNG, PNM, TUM depth, map YAML + image (image_targets.cpp)
std::vector<Target> journal_targets();  ///< the mapper's journal (journal_target.cpp)
std::vector<Target> slam_map_targets();  ///< a saved SLAM map (slam_map_target.cpp)
std::vector<Target> estimator_targets();  ///< the estimator fed a stream of inputs (estimator_target.cpp)
#if KESTREL_FUZZ_STATION
std::vector<Target> station_targets();  ///< the ground station's commands and updates (station_targets.cpp)
#endif

}  // namespace kestrel::fuzz
