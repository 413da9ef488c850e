#pragma once
// PlaybackClock: when each event of a timed replay is due on the wall clock, under play,
// pause, seek and speed changes (`kestrel replay --control`, a recorded flight under review).
//
// The clock holds an anchor: log time `anchor_log_us` is played at wall time `anchor_wall_s`,
// and from there log time runs `speed` times as fast as the wall's. Every transport command
// re-anchors at the current position, so a change never makes the log jump: pause holds the
// position, play resumes from it, a new speed takes effect from it, and a seek moves it.
// Times are passed in (wall seconds from any fixed origin); nothing here reads a clock.
//
// Invariants: speed is positive and finite; while paused nothing is due (due_s is +infinity) and the
// position stands still; position_us never goes backwards except by seek().

#include <cstdint>

namespace kestrel::replay {

class PlaybackClock {
 public:
  /// Playing at `speed` from log time `start_log_us` at wall time `now_s`. Throws
  /// std::invalid_argument on a speed that is not positive and finite.
  PlaybackClock(double speed, int64_t start_log_us, double now_s);

  /// The wall time at which the event stamped `log_us` is due (+infinity while paused; in
  /// the past for an event behind the position, which then goes out at once).
  double due_s(int64_t log_us) const;
  /// The log time being played at wall time `now_s`.
  int64_t position_us(double now_s) const;

  void pause(double now_s);
  void play(double now_s);
  /// Throws std::invalid_argument on a speed that is not positive and finite.
  void set_speed(double speed, double now_s);
  /// The position becomes `log_us` at `now_s`; paused or playing as before.
  void seek(int64_t log_us, double now_s);
  /// A gap in the log played shorter by `cut_us` >= 0 (the replay's --max-gap): the position
  /// jumps ahead by it (at most to the end of int64), so that the event after the gap is due sooner.
  void skip(int64_t cut_us);

  bool paused() const { return paused_; }
  double speed() const { return speed_; }

 private:
  double speed_;
  bool paused_ = false;
  int64_t anchor_log_us_;
  double anchor_wall_s_;
};

}  // namespace kestrel::replay
