// kestrel-goto: sends the vehicle somewhere. Asks the planner for a path from the vehicle's
// current STATE to --goal (PLAN_REQUEST), prints the answer and, with --wait, follows STATE
// along the plan until the vehicle has come to its end within --arrive-radius of the goal
// (kestrel-follow flies the PLAN). Its progress along the plan is kept as kestrel-follow keeps
// it (control/follower_node.h): a plan that passes near the goal on its way (a detour the
// belief model chose) is not "arrived" there, with the vehicle still flying.
// A "no path" answer (no map yet, start or goal not in known free space, no way) is asked
// again every second for --retry-for seconds from the first answer: at start-up the map
// changes fast. A request without an answer is sent again every --resend-after seconds (a
// planner restarted since never saw it; a UDP datagram can be lost). Those seconds are the
// sensor time of STATE. Exit 0: planned (and arrived); 1: no path, or no answer / no arrival
// within --timeout (wall seconds).
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <optional>

#include "common/cli.h"
#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "control/follower_node.h"
#include "kestrel/plan_request_t.hpp"
#include "kestrel/plan_t.hpp"
#include "kestrel/state_t.hpp"

namespace {

using namespace kestrel;

struct Options {
  std::string lcm_url;
  std::vector<double> goal;
  std::string planner = "brm";
  double max_trace = 0.0;
  bool wait = false;
  double arrive_radius_m = 0.15;
  double timeout_s = 60.0;
  double retry_s = 5.0;
  double resend_s = 2.0;
};

int run(const Options& o) {
  transport::Node node("goto", o.lcm_url);
  node.advertise(channel::kPlanRequest);
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  const int64_t request_id = std::chrono::duration_cast<std::chrono::microseconds>(
                                 std::chrono::system_clock::now().time_since_epoch()).count();
  // Asking again is timed on the sensor time of STATE, and the request goes out from the STATE
  // handler: under lock-step (sim --lockstep) it is then an output like any other, and the
  // same flight asks at the same instants on any machine. Only giving up (--timeout) is wall time.
  std::optional<kestrel::state_t> state;
  std::optional<kestrel::plan_t> plan;
  bool sent = false;
  int64_t sent_utime = 0;
  std::optional<int64_t> first_answer_utime;  // --retry-for counts from the planner's first answer
  const auto seconds_since = [](int64_t utime, int64_t since) { return 1e-6 * static_cast<double>(utime - since); };
  const auto send_request = [&] {
    kestrel::plan_request_t r{};
    r.utime = state->utime;
    r.request_id = request_id;
    r.start_mode = kestrel::plan_request_t::START_FROM_STATE;
    for (int i = 0; i < 4; ++i) r.goal[i] = o.goal[static_cast<size_t>(i)];
    r.planner = o.planner == "prm"             ? kestrel::plan_request_t::PLANNER_PRM
                : o.planner == "brm-dominance" ? kestrel::plan_request_t::PLANNER_BRM_DOMINANCE
                                               : kestrel::plan_request_t::PLANNER_BRM;
    r.objective = o.max_trace > 0.0 ? kestrel::plan_request_t::OBJECTIVE_SHORTEST_BOUNDED
                                    : kestrel::plan_request_t::OBJECTIVE_MIN_GOAL_UNCERTAINTY;
    r.max_covariance_trace = o.max_trace;
    node.publish(channel::kPlanRequest, r);
    sent = true;
    sent_utime = state->utime;
    spdlog::info("asked for a path from ({:.2f}, {:.2f}, {:.2f}) to ({:.2f}, {:.2f}, {:.2f})",
                 state->T_world_body.position[0], state->T_world_body.position[1],
                 state->T_world_body.position[2], o.goal[0], o.goal[1], o.goal[2]);
  };
  const auto no_path_yet = [&](int64_t now_utime) {
    return plan && plan->status != kestrel::plan_t::STATUS_OK && plan->status != kestrel::plan_t::STATUS_BAD_REQUEST &&
           seconds_since(now_utime, *first_answer_utime) < o.retry_s;
  };
  // The vehicle's progress along the plan, as the follower flying it keeps it; every STATE.
  // Never "off the path" here: holding the vehicle is kestrel-follow's call, with its own
  // --max-deviation; goto only waits for the end.
  control::FollowerNodeOptions progress_options;
  progress_options.follower.arrive_radius_m = o.arrive_radius_m;
  progress_options.follower.max_deviation_m = std::numeric_limits<double>::infinity();
  progress_options.command_period_s = 0.0;
  // The progress of the vehicle as STATE has it (arrival is judged on STATE): no jump smoothing.
  progress_options.smoothing.min_jump_m = std::numeric_limits<double>::infinity();
  control::FollowerNode progress(progress_options);
  node.subscribe<kestrel::state_t>(channel::kState, [&](const kestrel::state_t& m) {
    if (m.status != kestrel::state_t::STATUS_OK && m.status != kestrel::state_t::STATUS_DEGRADED) return;
    state = m;
    progress.on_state(m);
    // No map yet, or no way on it yet: at start-up the map changes fast (the first keyframes,
    // SLAM moving it into the estimator's world), so ask again each second for --retry-for.
    if (no_path_yet(m.utime) && seconds_since(m.utime, sent_utime) >= 1.0) {
      spdlog::info("no path yet ({}); asking again", plan->message);
      plan.reset();
      sent = false;
    }
    if (sent && !plan && seconds_since(m.utime, sent_utime) >= o.resend_s) {
      spdlog::info("no answer after {:.1f} s (is the planner running?); asking again", seconds_since(m.utime, sent_utime));
      sent = false;
    }
    if (!sent) send_request();
  }, 400);  // as kestrel-follow: a stalled goto must not lose the states its progress needs
  node.subscribe<kestrel::plan_t>(channel::kPlan, [&](const kestrel::plan_t& m) {
    if (m.request_id != request_id) return;
    // A plan the follower refuses (a non-finite waypoint: InputError, logged by the node) is
    // no answer: asked again after --resend-after.
    if (m.status == kestrel::plan_t::STATUS_OK) progress.on_plan(m);
    plan = m;
    if (!first_answer_utime) first_answer_utime = state ? state->utime : m.utime;
  });
  while (elapsed() < o.timeout_s && node.spin_once(100)) {
    if (!plan || (state && no_path_yet(state->utime))) continue;
    if (plan->status != kestrel::plan_t::STATUS_OK || !o.wait) break;
    if (state) {
      const auto& p = state->T_world_body.position;
      const double d = std::hypot(p[0] - o.goal[0], p[1] - o.goal[1], p[2] - o.goal[2]);
      if (d <= o.arrive_radius_m && progress.follower().status() == control::FollowStatus::kArrived) {
        std::cout << "arrived: " << d << " m from the goal after " << elapsed() << " s\n";
        return kExitOk;
      }
    }
  }
  if (!sent) {
    std::cerr << "kestrel-goto: error: no STATE within " << o.timeout_s << " s (is the estimator running?)\n";
    return kExitFailure;
  }
  if (!plan) {
    std::cerr << "kestrel-goto: error: no PLAN within " << o.timeout_s << " s (is the planner running?)\n";
    return kExitFailure;
  }
  if (plan->status != kestrel::plan_t::STATUS_OK) {
    std::cerr << "kestrel-goto: no path: " << plan->message << "\n";
    return kExitFailure;
  }
  std::cout << "# x y z yaw tr(Sigma)   length " << plan->length << " m, planned in " << plan->planning_ms << " ms\n";
  for (int i = 0; i < plan->num_waypoints; ++i) {
    const auto& w = plan->waypoints[static_cast<size_t>(i)];
    std::cout << w[0] << " " << w[1] << " " << w[2] << " " << w[3] << " " << plan->covariance_trace[static_cast<size_t>(i)] << "\n";
  }
  if (o.wait) {
    std::cerr << "kestrel-goto: error: not within " << o.arrive_radius_m << " m of the goal after " << o.timeout_s << " s\n";
    return kExitFailure;
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("goto", "Plan from the vehicle's STATE to a goal (PLAN_REQUEST -> PLAN) and, with --wait, wait for arrival");
  Options o;
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--goal", o.goal, "Goal x y z yaw (world frame: the estimator's, m and rad)")->expected(4)->required();
  app.add_option("--planner", o.planner, "brm (Algorithm 1), brm-dominance (covariance dominance) or prm")
      ->check(CLI::IsMember({"brm", "brm-dominance", "prm"}))
      ->capture_default_str();
  app.add_option("--max-trace", o.max_trace, "Shortest path with tr(Sigma) below this (0: least uncertain goal)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_flag("--wait", o.wait, "Wait until the vehicle is at the goal");
  app.add_option("--arrive-radius", o.arrive_radius_m, "Arrived within this of the goal (m)")->check(cli::Positive)->capture_default_str();
  app.add_option("--timeout", o.timeout_s, "Give up after this many wall seconds")->check(cli::Positive)->capture_default_str();
  app.add_option("--resend-after", o.resend_s, "Send the request again after this many seconds of STATE without an answer")
      ->check(cli::Positive)->capture_default_str();
  app.add_option("--retry-for", o.retry_s, "Ask again each second of STATE while the answer is no path, for this many seconds from the first answer")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  return app.run(argc, argv, [&] {
    for (double v : o.goal)
      if (!std::isfinite(v)) throw CLI::ValidationError("--goal: not a finite number");
    return run(o);
  });
}
