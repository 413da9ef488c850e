#include "tools/link/split_flight.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <vector>

#include "common/atomic_file.h"
#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/plan_t.hpp"
#include "kestrel/vo_update_t.hpp"

namespace kestrel::link {
namespace {

namespace fs = std::filesystem;

std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The last number that `pattern`'s first group matches in `text`, or -1.
int last_match(const std::string& text, const std::string& pattern) {
  const std::regex re(pattern);
  int value = -1;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), re); it != std::sregex_iterator(); ++it)
    value = std::stoi((*it)[1].str());
  return value;
}

int64_t read_mark_us(const fs::path& path) {  // `date +%s%N` in microseconds, or -1
  std::ifstream in(path);
  long long ns = -1;
  if (!(in >> ns)) return -1;
  return ns / 1000;
}

}  // namespace

SplitFlightResult fly_split(const SplitFlightOptions& o) {
  SplitFlightResult r;
  fs::create_directories(o.out_dir);
  const fs::path out = fs::absolute(o.out_dir);
  const Eigen::Vector3d start(8.0, 3.5, 1.3);  // the room's take-off pose
  const Eigen::Vector3d back(9.0, 3.5, 1.3);   // where it returns: 1 m ahead of the start, so mapped
  const auto bin = [&](const char* tool) { return (o.bin_dir / (std::string("kestrel-") + tool)).string(); };
  const std::string go = bin("goto") + " --wait --arrive-radius 0.1 --timeout 20 --goal ";
  {
    // The ground station's user, in the offboard namespace. A user asks again once when a
    // request was not flown: a PLAN lost on its way down is sent again by no one (goto heard
    // it at the ground station). Then it waits to be stopped with the others.
    std::ostringstream user;
    user << "cd " << quoted(out.string()) << "\n"
         << "sleep " << o.hover_s << "; date +%s%N > mark_a\n"
         << "for i in 1 2; do " << go << "9.5 3.5 1.3 0 >> goto_out.txt 2>&1; G1=$?; [ $G1 -eq 0 ] && break; done\n"
         << "echo $i > attempts_out\n"
         << "for i in 1 2; do " << go << "9 3.5 1.3 0 >> goto_back.txt 2>&1; G2=$?; [ $G2 -eq 0 ] && break; done\n"
         << "echo $i > attempts_back; date +%s%N > mark_b; echo \"$G1 $G2\" > goto_status.txt\n"
         << "exec sleep 100000\n";
    write_file_atomically((out / "user.sh").string(), user.str());
  }
  {
    // The recorder onboard and the user offboard are processes of the set, so that the
    // launcher puts them in their namespaces (no nsenter, no root). A process-set command
    // is split on blanks: the folder's path must have none.
    std::ostringstream sets;
    sets << "# the split flight's processes (tools/link/split_flight.h)\n"
            "processes:\n"
            "  - {name: vo, command: vo, side: onboard}\n"
            "  - {name: estimator, command: \"estimator --await-world 1 --init-position 8,3.5,1.3\", side: onboard}\n"
            "  - {name: follow, command: follow, side: onboard}\n"
            "  - {name: recorder, command: \"lcm-logger -q -c (GROUND_TRUTH|STATE|PLAN|SLAM_CORRECTION|VO_UPDATE) "
         << (out / "onboard.lcmlog").string() << "\", side: onboard}\n"
            "  - {name: slam, command: slam, side: offboard}\n"
            "  - {name: mapper, command: \"mapper --publish-period 1\", side: offboard}\n"
            "  - {name: planner, command: \"planner --height 1.3 --sensor kinect\", side: offboard}\n"
            "  - {name: user, command: \"sh "
         << (out / "user.sh").string() << "\", side: offboard}\n";
    write_file_atomically((out / "sets.yaml").string(), sets.str());
  }
  const std::string link_options = fmt::format("--loss {} --delay {} --jitter {} --rate {} --seed {}", o.loss_percent,
                                               o.delay_ms, o.jitter_ms, o.rate_mbit, o.seed);
  const std::string script = fmt::format(
      "cd {out}; rm -f launch_status.txt goto_status.txt mark_a mark_b goto_out.txt goto_back.txt onboard.lcmlog; "
      "{launch} all --link --link-options {link} --sets sets.yaml --status-period 0 --log-dir logs "
      "--source {source} > launch.txt 2>&1; echo $? > launch_status.txt",
      fmt::arg("out", quoted(out.string())), fmt::arg("launch", quoted(bin("launch"))),
      fmt::arg("link", quoted(link_options)),
      fmt::arg("source", quoted(fmt::format("sim --world room --flight vehicle --duration {} --seed {} -q "
                                            "--rgb-encoding raw --depth-encoding raw",
                                            o.duration_s, o.seed))));
  if (out.string().find_first_of(" \t") != std::string::npos) {
    r.problems = "the flight's folder has a blank in its path: " + out.string() + "\n";
    return r;
  }
  [[maybe_unused]] const int ignored = std::system(("sh -c " + quoted(script)).c_str());

  auto problem = [&](const std::string& what) { r.problems += what + "\n"; };
  {
    std::ifstream launch(out / "launch_status.txt"), user(out / "goto_status.txt");
    if (!(launch >> r.launch_exit)) problem("no launch_status.txt: the flight's script failed");
    if (!(user >> r.goto_out_exit >> r.goto_back_exit)) problem("no goto_status.txt: the user's requests did not end");
  }
  // Where it holds at the end: where the last plan that was flown took it (a request that was
  // never answered with a path leaves it where it was).
  const Eigen::Vector3d out_goal(9.5, 3.5, 1.3);
  const Eigen::Vector3d end_hold = r.goto_back_exit == 0 ? back : r.goto_out_exit == 0 ? out_goal : start;
  for (const auto& [file, attempts] : {std::pair{"attempts_out", &r.goto_out_attempts}, std::pair{"attempts_back", &r.goto_back_attempts}}) {
    std::ifstream in(out / file);
    in >> *attempts;
  }
  const int64_t mark_a = read_mark_us(out / "mark_a"), mark_b = read_mark_us(out / "mark_b");
  if (mark_a < 0 || mark_b < 0) problem("no time marks");

  // The onboard log: truth while holding, corrections and plans as they arrived.
  int64_t first_truth = -1;
  int64_t last_state = 0;
  double sum = 0.0;
  try {
    transport::LogReader log((out / "onboard.lcmlog").string());
    while (auto e = log.next()) {
      const auto& data = e->data;
      if (e->channel == channel::kGroundTruth) {
        if (first_truth < 0) first_truth = e->timestamp;
        const bool hold_start = e->timestamp >= first_truth + 3'000'000 && e->timestamp < mark_a;
        const bool hold_back = e->timestamp >= mark_b + 2'000'000;
        if (!hold_start && !hold_back) continue;
        const auto m = transport::decode_message<kestrel::ground_truth_t>(data.data(), data.size(), "GROUND_TRUTH");
        const double d =
            (transport::from_message(m.T_world_frame, "GROUND_TRUTH").translation() - (hold_start ? start : end_hold)).norm();
        sum += d;
        r.deviation_max_m = std::max(r.deviation_max_m, d);
        ++r.hover_samples;
      } else if (e->channel == channel::kState) {
        if (r.states++ > 0) r.state_max_gap_s = std::max(r.state_max_gap_s, 1e-6 * static_cast<double>(e->timestamp - last_state));
        last_state = e->timestamp;
      } else if (e->channel == channel::kSlamCorrection) {
        ++r.corrections_received;
      } else if (e->channel == channel::kVoUpdate) {
        const auto m = transport::decode_message<kestrel::vo_update_t>(data.data(), data.size(), "VO_UPDATE");
        if (m.status != kestrel::vo_update_t::STATUS_OK && m.status != kestrel::vo_update_t::STATUS_NO_REFERENCE)
          r.vo_failures.push_back({m.utime, m.status, m.num_features, m.num_matches, m.num_inliers});
      } else if (e->channel == channel::kPlan) {
        ++r.plans_received;
        r.plans_answered +=
            transport::decode_message<kestrel::plan_t>(data.data(), data.size(), "PLAN").status == kestrel::plan_t::STATUS_OK;
      }
    }
  } catch (const std::exception& e) {
    problem(std::string("onboard log: ") + e.what());
  }
  if (r.hover_samples > 0) r.deviation_mean_m = sum / r.hover_samples;

  const fs::path logs = out / "logs";
  r.corrections_applied = last_match(read_text(logs / "estimator.log"), R"(corrections (\d+) applied)");
  r.mapper_keyframes = last_match(read_text(logs / "mapper.log"), R"(\d+ frames \((\d+) inserted)");
  r.slam_keyframes = last_match(read_text(logs / "slam.log"), R"((\d+) keyframes \(\d+ thinned)");
  const std::string vo = read_text(logs / "vo.log");
  r.vo_frames = last_match(vo, R"((\d+) frames, \d+ with a motion)");
  r.vo_motions = last_match(vo, R"(\d+ frames, (\d+) with a motion)");
  if (r.corrections_applied < 0) problem("no estimator counts in logs/estimator.log");
  if (r.mapper_keyframes < 0) problem("no mapper counts in logs/mapper.log");
  try {
    const auto j = nlohmann::json::parse(read_text(logs / "link.json"));
    for (const char* way : {"up", "down"}) {
      r.datagrams_offered += j.at(way).at("offered").get<int64_t>();
      r.datagrams_lost += j.at(way).at("lost").get<int64_t>();
      r.datagrams_queue_full += j.at(way).at("queue_full").get<int64_t>();
    }
    const double seconds = j.at("seconds").get<double>();
    if (seconds > 0) r.up_mbit_s = j.at("up").at("bytes_offered").get<double>() * 8e-6 / seconds;
  } catch (const std::exception& e) {
    problem(std::string("logs/link.json: ") + e.what());
  }
  return r;
}

}  // namespace kestrel::link
