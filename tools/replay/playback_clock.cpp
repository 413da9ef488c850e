#include "tools/replay/playback_clock.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

namespace kestrel::replay {
namespace {

double checked_speed(double speed) {
  if (!(speed > 0.0 && std::isfinite(speed)))
    throw std::invalid_argument("playback speed " + std::to_string(speed) + " is not a positive number");
  return speed;
}

}  // namespace

PlaybackClock::PlaybackClock(double speed, int64_t start_log_us, double now_s)
    : speed_(checked_speed(speed)), anchor_log_us_(start_log_us), anchor_wall_s_(now_s) {}

double PlaybackClock::due_s(int64_t log_us) const {
  if (paused_) return std::numeric_limits<double>::infinity();
  // The difference in double: two int64 stamps may lie further apart than an int64 holds.
  return anchor_wall_s_ + 1e-6 * (static_cast<double>(log_us) - static_cast<double>(anchor_log_us_)) / speed_;
}

int64_t PlaybackClock::position_us(double now_s) const {
  if (paused_ || !(now_s > anchor_wall_s_)) return anchor_log_us_;
  // In double, then bounded to what an int64 holds: near its end the sum would overflow.
  const double at = static_cast<double>(anchor_log_us_) + (now_s - anchor_wall_s_) * speed_ * 1e6;
  return at >= 9.2e18 ? INT64_MAX : static_cast<int64_t>(std::llround(at));
}

void PlaybackClock::skip(int64_t cut_us) {
  anchor_log_us_ = cut_us > INT64_MAX - anchor_log_us_ ? INT64_MAX : anchor_log_us_ + cut_us;
}

void PlaybackClock::pause(double now_s) {
  if (paused_) return;
  anchor_log_us_ = position_us(now_s);
  anchor_wall_s_ = now_s;
  paused_ = true;
}

void PlaybackClock::play(double now_s) {
  if (!paused_) return;
  anchor_wall_s_ = now_s;
  paused_ = false;
}

void PlaybackClock::set_speed(double speed, double now_s) {
  const double checked = checked_speed(speed);
  anchor_log_us_ = position_us(now_s);
  anchor_wall_s_ = now_s;
  speed_ = checked;
}

void PlaybackClock::seek(int64_t log_us, double now_s) {
  anchor_log_us_ = log_us;
  anchor_wall_s_ = now_s;
}

}  // namespace kestrel::replay
