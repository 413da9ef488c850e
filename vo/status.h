#pragma once
// What became of a frame, in words a user can act on. The values are those of
// vo_update_t.STATUS_* (lcmtypes/vo_update_t.lcm), so the process copies them as they are.

#include <cstdint>

namespace kestrel::vo {

enum class VoStatus : int8_t {
  kOk = 0,
  kNoReference = 1,           ///< first frame, or first after a reset: it becomes the reference
  kInsufficientFeatures = 2,  ///< too few FAST corners (dark, blurred or textureless image)
  kInsufficientDepth = 3,     ///< too few corners with a depth reading (too close, too far, no depth)
  kInsufficientMatches = 4,   ///< too few matches with the reference (fast motion, new view)
  kInsufficientInliers = 5,   ///< the matches do not agree on a rigid motion
  kOptimizationFailure = 6,   ///< the reprojection refinement diverged or lost its inliers
  kBadInput = 7,              ///< invalid frame: size, type, camera, or time stamp not increasing
};

/// "ok", "too few features", ...
const char* to_string(VoStatus status);

/// True when the frame carries a motion estimate.
inline bool has_motion(VoStatus s) { return s == VoStatus::kOk; }

}  // namespace kestrel::vo
