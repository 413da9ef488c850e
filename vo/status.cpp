#include "vo/status.h"

namespace kestrel::vo {

const char* to_string(VoStatus status) {
  switch (status) {
    case VoStatus::kOk: return "ok";
    case VoStatus::kNoReference: return "no reference";
    case VoStatus::kInsufficientFeatures: return "too few features";
    case VoStatus::kInsufficientDepth: return "too little valid depth";
    case VoStatus::kInsufficientMatches: return "too few matches";
    case VoStatus::kInsufficientInliers: return "too few inliers";
    case VoStatus::kOptimizationFailure: return "optimisation failure";
    case VoStatus::kBadInput: return "bad input";
  }
  return "unknown";
}

}  // namespace kestrel::vo
