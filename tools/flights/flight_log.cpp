#include "tools/flights/flight_log.h"

#include <map>

#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "metrics/evaluate.h"
#include "tools/eval/log_input.h"
#include "tools/eval/trajectory_input.h"

namespace kestrel::flights {

FlightRecord read_flight_log(const std::string& path) {
  FlightRecord r;
  int64_t graph_revision = -1;
  transport::LogReader log(path);
  while (auto e = log.next()) {
    const auto& d = e->data;
    try {
      if (e->channel == channel::kGroundTruth) {
        const auto m = transport::decode_message<kestrel::ground_truth_t>(d.data(), d.size(), e->channel);
        r.truth.push_back({m.utime, transport::from_message(m.T_world_frame, "GROUND_TRUTH").translation()});
      } else if (e->channel == channel::kState) {
        const auto m = transport::decode_message<kestrel::state_t>(d.data(), d.size(), e->channel);
        StateSample s;
        s.utime = m.utime;
        s.usable = m.status == kestrel::state_t::STATUS_OK || m.status == kestrel::state_t::STATUS_DEGRADED;
        s.p = transport::from_message(m.T_world_body, "STATE").translation();
        if (m.cov_dim >= 3)
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) s.P(i, j) = m.covariance[static_cast<size_t>(i)][static_cast<size_t>(j)];
        r.states.push_back(s);
      } else if (e->channel == channel::kVoUpdate) {
        const auto m = transport::decode_message<kestrel::vo_update_t>(d.data(), d.size(), e->channel);
        ++r.vo_frames;
        r.vo_failures += m.status != kestrel::vo_update_t::STATUS_OK;
      } else if (e->channel == channel::kSlamGraph) {
        const auto m = transport::decode_message<kestrel::slam_graph_t>(d.data(), d.size(), e->channel);
        // A newer graph has a later revision, or the same one with keyframes added since (the
        // revision counts optimisations only); an older revision is a stale duplicate.
        if (m.revision < graph_revision) continue;
        graph_revision = m.revision;
        r.keyframes = m.num_keyframes;
        r.loop_closures = 0;
        for (const auto& edge : m.edges) r.loop_closures += edge.kind == kestrel::slam_edge_t::KIND_LOOP_CLOSURE;
      }
    } catch (const InputError&) {
      // A corrupt message is left out (as kestrel eval does); the rest still scores.
    }
  }
  if (r.truth.empty()) throw InputError(path + ": no GROUND_TRUTH in the flight's recording");
  if (r.vo_frames > 0) {
    // The VO's gross frames, by kestrel eval's rule (velocity error above 1 m/s), against the truth.
    eval::TrajectoryInput gt = eval::read_log_input(path, {channel::kGroundTruth});
    const eval::TrajectoryInput vo = eval::read_log_input(path, {channel::kVoUpdate});
    eval::reconcile_frames(gt, vo);
    metrics::EvalOptions options;
    try {
      r.vo_gross = static_cast<int64_t>(
          metrics::evaluate(vo.frame_utimes, vo.trajectory, gt.trajectory, options).velocity.gross.total());
    } catch (const metrics::NoOverlapError&) {
      r.vo_gross = r.vo_frames;
    }
  }
  return r;
}

}  // namespace kestrel::flights
