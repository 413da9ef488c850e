// kestrel soak as a user runs it, short: one simulated minute of the whole system flying the
// room's loop (sim vehicle, vo, estimator, follow, slam, mapper; lock-step), every process
// sampled; a soak whose SLAM is killed half-way; and the usage errors.

#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "test/support/test_support.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;

const std::set<std::string> kProcesses = {"sim", "vo", "estimator", "follow", "slam", "mapper"};

struct Row {
  double wall_s, sim_s;
  std::string process;
  int pid;
  double rss_mb;
};

std::vector<Row> read_samples(const fs::path& csv) {
  std::istringstream in(test::read_file(csv));
  std::string line;
  std::getline(in, line);
  std::vector<Row> rows;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string f[9];
    for (auto& x : f) std::getline(fields, x, ',');
    rows.push_back({std::stod(f[0]), std::stod(f[1]), f[2], std::stoi(f[3]), std::stod(f[4])});
  }
  return rows;
}

TEST(Soak, HalfAMinuteOfTheWholeSystemIsSampledAndReportedPerProcess) {
  if (!test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
  test::TempDir dir;
  const auto t0 = std::chrono::steady_clock::now();
  // Half a minute: long enough for a warm-up (a third of it) and a fit over 20 samples; the
  // soak's figures come from its 30-minute runs (tools/soak/README.md).
  const double run_s = 30.0;
  const auto r = test::run({test::tool("soak").string(), "--minutes", std::to_string(run_s / 60.0), "--sample-period",
                            "1", "--out", dir.path().string()},
                           300.0);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Every process sampled, over the whole run, with memory.
  const auto rows = read_samples(dir / "samples.csv");
  std::map<std::string, std::vector<Row>> by_process;
  for (const Row& row : rows) by_process[row.process].push_back(row);
  std::set<std::string> sampled;
  for (const auto& [name, rs] : by_process) sampled.insert(name);
  EXPECT_EQ(sampled, kProcesses);
  for (const auto& [name, rs] : by_process) {
    EXPECT_GE(rs.size(), 10u) << name;
    for (const Row& row : rs) {
      EXPECT_GT(row.rss_mb, 1.0) << name;
      EXPECT_LT(row.rss_mb, 4000.0) << name;
      EXPECT_EQ(row.pid, rs.front().pid) << name << ": restarted";
    }
    EXPECT_GT(rs.back().sim_s, run_s - 5.0) << name;
  }
  // The simulated time reached the run's length, and the samples follow it.
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir / "soak.json"));
  EXPECT_GT(j["sim_s"].get<double>(), run_s - 2.5) << j.dump(2);
  EXPECT_LE(j["sim_s"].get<double>(), run_s + 0.5) << j.dump(2);
  EXPECT_TRUE(j["usable"].get<bool>());
  EXPECT_EQ(j["failure"], "");
  // 30 frames a second measured by the VO; the vehicle flew the route (0.5 m/s less the start).
  EXPECT_GT(j["frames"].get<int>(), 25 * run_s) << j.dump(2);
  EXPECT_GT(j["distance_m"].get<double>(), 0.25 * run_s) << j.dump(2);
  EXPECT_LT(j["distance_m"].get<double>(), 0.67 * run_s) << j.dump(2);
  EXPECT_GE(j["keyframes"].get<int>(), 5) << j.dump(2);
  ASSERT_EQ(j["processes"].size(), kProcesses.size()) << j.dump(2);
  for (const auto& p : j["processes"]) {
    const std::string name = p["process"];
    EXPECT_TRUE(kProcesses.count(name)) << name;
    EXPECT_FALSE(p["died"].get<bool>()) << name;
    EXPECT_GT(p["rss_warmup_mb"].get<double>(), 1.0) << name;
    EXPECT_GT(p["rss_end_mb"].get<double>(), 1.0) << name;
    EXPECT_GE(p["rss_peak_mb"].get<double>(), p["rss_end_mb"].get<double>()) << name;
    // The warm-up is a third of a short run; the fit is over the last two thirds.
    EXPECT_NEAR(p["warmup_at_s"].get<double>(), run_s / 3.0, 5.0) << name;
    EXPECT_GE(p["fit_samples"].get<int>(), 5) << name;
    EXPECT_TRUE(p["growth_mb_per_10min"].is_number()) << name;
    EXPECT_TRUE(p["verdict"] == "flat" || p["verdict"] == "grows") << name << ": " << p["verdict"];
    // Each process spends CPU on the frames, and none more than the 33 ms a frame lasts x 2 cores.
    EXPECT_GT(p["cpu_ms_per_frame"].get<double>(), 0.0) << name;
    EXPECT_LT(p["cpu_ms_per_frame"].get<double>(), 66.0) << name;
  }
  const std::string report = test::read_file(dir / "report.md");
  for (const std::string& name : kProcesses) EXPECT_NE(report.find("| " + name + " | "), std::string::npos) << name;
  EXPECT_GT(fs::file_size(dir / "soak.png"), 10000u);
  EXPECT_TRUE(fs::exists(dir / "progress.csv"));
  for (const std::string& name : kProcesses) EXPECT_TRUE(fs::exists(dir / "flight" / (name + ".log"))) << name;
  EXPECT_FALSE(fs::exists(dir / "flight" / "flight.lcmlog"));  // a soak records nothing
  std::cout << "the " << run_s << " s soak took " << wall_s << " s of wall time\n";
}

// SLAM killed while the system flies: the soak ends with 1, naming it, and still writes what it
// sampled until then.
TEST(Soak, AProcessKilledDuringTheSoakIsReportedAndTheExitIsOne) {
  if (!test::can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "no network namespace available";
  test::TempDir dir;
  std::thread killer([&] {
    // samples.csv is written every 10 rounds of samples; kill SLAM once it shows a pid.
    for (int i = 0; i < 600; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      if (!fs::exists(dir / "samples.csv")) continue;
      for (const Row& row : read_samples(dir / "samples.csv")) {
        if (row.process == "slam" && row.sim_s > 5.0) {
          ::kill(row.pid, SIGKILL);
          return;
        }
      }
    }
  });
  const auto r = test::run({test::tool("soak").string(), "--minutes", "1", "--sample-period", "0.3", "--out",
                            dir.path().string()},
                           300.0);
  killer.join();
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("slam killed by SIGKILL"), std::string::npos) << r.err;
  const nlohmann::json j = nlohmann::json::parse(test::read_file(dir / "soak.json"));
  EXPECT_LT(j["sim_s"].get<double>(), 55.0);
  bool slam_died = false;
  for (const auto& p : j["processes"])
    if (p["process"] == "slam") slam_died = p["died"].get<bool>() && p["verdict"] == "died";
  EXPECT_TRUE(slam_died) << j.dump(2);
  EXPECT_NE(test::read_file(dir / "report.md").find("died: killed by SIGKILL"), std::string::npos);
}

TEST(Soak, UsageErrorsExitTwoNamingTheOption) {
  test::TempDir dir;
  const std::string tool = test::tool("soak").string();
  const auto zero = test::run({tool, "--minutes", "0", "--out", dir.path().string()});
  EXPECT_EQ(zero.exit_code, 2) << zero.err;
  EXPECT_NE(zero.err.find("--minutes"), std::string::npos) << zero.err;
  const auto world = test::run({tool, "--world", "atlantis", "--out", dir.path().string()});
  EXPECT_EQ(world.exit_code, 2) << world.err;
  EXPECT_NE(world.err.find("atlantis"), std::string::npos) << world.err;
  const auto period = test::run({tool, "--sample-period", "nan"});
  EXPECT_EQ(period.exit_code, 2) << period.err;
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

}  // namespace
}  // namespace kestrel
