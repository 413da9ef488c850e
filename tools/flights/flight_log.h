#pragma once
// A closed-loop flight's recording (`kestrel sim --lockstep --record`) read into a FlightRecord:
// GROUND_TRUTH and STATE positions with STATE's position covariance, the VO's failures and
// gross frames (scored with kestrel eval's rule against the truth), and SLAM's final graph.

#include <string>

#include "tools/flights/flight_score.h"

namespace kestrel::flights {

/// Throws InputError naming the file when it cannot be read or holds no GROUND_TRUTH; a
/// damaged log is read around the damage, as every kestrel log reader does.
FlightRecord read_flight_log(const std::string& path);

}  // namespace kestrel::flights
