#pragma once
// Small well-formed values the seeds of several targets are built from, so that a message
// target and the journal target start from the same camera and keyframes.

#include <cstdint>

#include "common/camera.h"
#include "kestrel/slam_keyframe_t.hpp"

namespace kestrel::fuzz {

/// A pinhole camera `width` × `height` pixels, about 63° across, centred: small enough that a
/// seed frame stays a few kilobytes.
PinholeCamera small_camera(int width, int height);

/// A keyframe `id` (its time too, in µs) at x = `x_m` m, 1 m up, looking along the world's axes,
/// its depth camera where its colour camera is.
kestrel::slam_keyframe_t keyframe(int64_t id, double x_m);

}  // namespace kestrel::fuzz
