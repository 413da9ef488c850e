#pragma once
// The vocabulary that ships with kestrel (slam/vocabulary/sim_k8l4.voc, built into the
// library): trained by kestrel-slam-vocabulary on frames rendered by the simulator's own
// worlds; slam/README.md says how, on what, and why it is the tools' default.

#include <memory>

#include "slam/place/vocabulary.h"

namespace kestrel::slam {

/// The built-in vocabulary, decoded on the first call and shared afterwards (thread-safe).
std::shared_ptr<const Vocabulary> builtin_vocabulary();

}  // namespace kestrel::slam
