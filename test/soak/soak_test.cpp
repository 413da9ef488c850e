// kestrel soak's figures on hand-made samples with known answers: the fitted growth and the
// verdict, the warm-up sample, the CPU per frame, a process that died, the CSV; a process's
// memory from /proc; and the route, one lap of the room's loop flight, repeated.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <sstream>

#include "common/numbers.h"
#include "drivers/sim/world_catalog.h"
#include "tools/soak/proc_memory.h"
#include "tools/soak/soak.h"
#include "tools/soak/soak_route.h"

namespace kestrel::soak {
namespace {

// A process sampled every 10 s of simulated time for `minutes`: RSS 100 MB, then `growth`
// MB per 10 min after `warm_s` (before it, 50 MB rising to 100: the warm-up), CPU 2 ms per
// frame at 30 frames a second.
std::vector<ProcessSample> process(const std::string& name, double minutes, double growth, double warm_s = 300.0) {
  std::vector<ProcessSample> out;
  for (double t = 0.0; t <= 60.0 * minutes + 1e-9; t += 10.0) {
    ProcessSample s;
    s.wall_s = 1.5 * t;
    s.sim_s = t;
    s.process = name;
    s.pid = 42;
    s.rss_mb = t < warm_s ? 50.0 + 50.0 * t / warm_s : 100.0 + growth * (t - warm_s) / 600.0;
    s.anon_mb = s.rss_mb - 20.0;
    s.frames = static_cast<int64_t>(std::lround(30.0 * t));
    s.cpu_s = 0.002 * static_cast<double>(s.frames);
    out.push_back(s);
  }
  return out;
}

std::vector<ProcessSample> merged(const std::vector<std::vector<ProcessSample>>& processes) {
  std::vector<ProcessSample> out;
  for (size_t i = 0; !processes.empty() && i < processes.front().size(); ++i)
    for (const auto& p : processes)
      if (i < p.size()) out.push_back(p[i]);
  return out;
}

std::vector<ProgressSample> progress(double minutes) {
  std::vector<ProgressSample> out;
  for (double t = 0.0; t <= 60.0 * minutes + 1e-9; t += 10.0)
    out.push_back({1.5 * t, t, static_cast<int64_t>(std::lround(30.0 * t)), 3, 2.5, 0.5 * t, 10, 2});
  return out;
}

const ProcessSummary& of(const Summary& s, const std::string& name) {
  for (const ProcessSummary& p : s.processes)
    if (p.process == name) return p;
  throw std::runtime_error("no summary of " + name);
}

TEST(SoakFit, ALineThroughExactPointsIsFoundAndTooFewPointsGiveNone) {
  const Line l = fit_line({0, 1, 2, 3}, {1, 3, 5, 7});
  EXPECT_NEAR(l.slope, 2.0, 1e-12);
  EXPECT_NEAR(l.intercept, 1.0, 1e-12);
  EXPECT_TRUE(std::isnan(fit_line({1, 1}, {2, 3}).slope));
  EXPECT_TRUE(std::isnan(fit_line({}, {}).slope));
}

TEST(SoakSummary, AProcessThatKeepsGrowingIsNotFlatAndOneThatStaysIs) {
  Criteria c;
  c.run_s = 1800.0;
  c.warmup_s = 300.0;
  c.flat_mb_per_10min = 2.0;
  const Summary s = summarise(merged({process("slam", 30, 12.0), process("vo", 30, 0.5)}), progress(30), c);
  ASSERT_EQ(s.processes.size(), 2u);
  EXPECT_TRUE(s.usable());
  EXPECT_FALSE(s.all_flat());
  const ProcessSummary& slam = of(s, "slam");
  EXPECT_EQ(slam.verdict, "grows");
  EXPECT_NEAR(slam.growth_mb_per_10min, 12.0, 1e-9);
  EXPECT_NEAR(slam.anon_growth_mb_per_10min, 12.0, 1e-9);
  // The warm-up is the first sample from 5 min; the fit the last two thirds (from 10 min).
  EXPECT_DOUBLE_EQ(slam.warmup_at_s, 300.0);
  EXPECT_NEAR(slam.rss_warmup_mb, 100.0, 1e-9);
  EXPECT_NEAR(slam.rss_end_mb, 100.0 + 12.0 * 2.5, 1e-9);
  EXPECT_NEAR(slam.rss_peak_mb, slam.rss_end_mb, 1e-9);
  EXPECT_DOUBLE_EQ(slam.fit_from_s, 600.0);
  EXPECT_EQ(slam.fit_samples, 121u);
  const ProcessSummary& vo = of(s, "vo");
  EXPECT_EQ(vo.verdict, "flat");
  EXPECT_NEAR(vo.growth_mb_per_10min, 0.5, 1e-9);
  EXPECT_NEAR(vo.cpu_ms_per_frame_early, 2.0, 1e-9);
  EXPECT_NEAR(vo.cpu_ms_per_frame_late, 2.0, 1e-9);
  // The system's pace: 1.5 s of wall per simulated second, 30 frames a second.
  EXPECT_NEAR(s.wall_ms_per_frame, 50.0, 1e-9);
  EXPECT_NEAR(s.vo_elapsed_ms, 2.5, 1e-9);
  EXPECT_DOUBLE_EQ(s.sim_s, 1800.0);
  EXPECT_EQ(s.frames, 54000);
  EXPECT_EQ(s.vo_failures, 3);
}

TEST(SoakSummary, TheWarmUpsRiseIsNotGrowth) {
  Criteria c;
  c.run_s = 1800.0;
  c.warmup_s = 300.0;
  // 50 MB in the first 5 min, none after: flat, though the end is twice the start.
  const Summary s = summarise(process("mapper", 30, 0.0), progress(30), c);
  EXPECT_EQ(of(s, "mapper").verdict, "flat");
  EXPECT_NEAR(of(s, "mapper").growth_mb_per_10min, 0.0, 1e-9);
  EXPECT_TRUE(s.all_flat());
}

TEST(SoakSummary, AProcessThatDiedIsSaidSoAndTooFewSamplesAreTooShort) {
  Criteria c;
  c.run_s = 1800.0;
  c.warmup_s = 300.0;
  auto samples = merged({process("vo", 30, 0.0), process("slam", 4, 0.0)});
  const Summary s = summarise(samples, progress(30), c, {{"slam", "killed by SIGKILL"}});
  EXPECT_EQ(of(s, "slam").verdict, "died");
  EXPECT_TRUE(of(s, "slam").died);
  EXPECT_EQ(of(s, "slam").died_how, "killed by SIGKILL");
  EXPECT_FALSE(s.all_flat());
  const Summary short_run = summarise(process("vo", 0.3, 0.0), progress(0.3), c);
  EXPECT_EQ(of(short_run, "vo").verdict, "too short");
  EXPECT_TRUE(std::isnan(of(short_run, "vo").rss_warmup_mb));
  EXPECT_FALSE(summarise({}, {}, c).usable());
}

TEST(SoakSummary, CpuPerFrameIsNotTakenAcrossARestart) {
  ProcessSample a, b;
  a.pid = 1, b.pid = 2;
  a.frames = 0, b.frames = 30;
  a.cpu_s = 0.0, b.cpu_s = 0.3;
  EXPECT_TRUE(std::isnan(cpu_ms_per_frame(a, b)));
  b.pid = 1;
  EXPECT_NEAR(cpu_ms_per_frame(a, b), 10.0, 1e-12);
  b.frames = 0;
  EXPECT_TRUE(std::isnan(cpu_ms_per_frame(a, b)));
}

TEST(SoakOutput, TheCsvHasOneLinePerSampleAndTheReportATableLinePerProcess) {
  Criteria c;
  const auto samples = merged({process("vo", 30, 0.0), process("slam", 30, 5.0)});
  const std::string csv = samples_csv(samples);
  std::istringstream in(csv);
  std::string header, line;
  std::getline(in, header);
  EXPECT_EQ(header, "wall_s,sim_s,process,pid,rss_MB,anon_MB,cpu_s,frames,cpu_ms_per_frame");
  size_t lines = 0;
  while (std::getline(in, line)) ++lines;
  EXPECT_EQ(lines, samples.size());
  EXPECT_NE(csv.find(",vo,42,50.000,30.000,0.000,0,\n"), std::string::npos) << csv.substr(0, 300);
  const Summary s = summarise(samples, progress(30), c);
  const std::string md = markdown(s, "heading", "");
  EXPECT_NE(md.find("| slam | 100.0 MB | 112.5 MB | 112.5 MB | 5.00 MB |"), std::string::npos) << md;
  EXPECT_NE(md.find("| grows |"), std::string::npos) << md;
  EXPECT_NE(md.find("| flat |"), std::string::npos) << md;
  const nlohmann::json j = to_json(s, "");
  ASSERT_EQ(j["processes"].size(), 2u);
  EXPECT_EQ(j["processes"][1]["verdict"], "grows");
  EXPECT_NEAR(j["processes"][1]["growth_mb_per_10min"].get<double>(), 5.0, 1e-9);
}

TEST(ProcMemory, TheStatusTextIsReadAndThisProcessHasMemory) {
  const auto m = parse_status("Name:\tx\nVmPeak:\t  9000 kB\nVmRSS:\t    2000 kB\nRssAnon:\t    1000 kB\n");
  ASSERT_TRUE(m);
  EXPECT_NEAR(m->rss_mb, 2.048, 1e-12);
  EXPECT_NEAR(m->anon_mb, 1.024, 1e-12);
  EXPECT_FALSE(parse_status("Name:\tzombie\nState:\tZ\n"));
  EXPECT_FALSE(parse_status("VmRSS:\t-5 kB\n"));
  const auto self = process_memory(::getpid());
  ASSERT_TRUE(self);
  EXPECT_GT(self->rss_mb, 1.0);
  EXPECT_GT(self->anon_mb, 0.0);
  EXPECT_LE(self->anon_mb, self->rss_mb);
  EXPECT_FALSE(process_memory(-1));
}

TEST(SoakRoute, TheRoomsLoopIsOneClosedLapRepeatedWholeAndEndingAtItsStart) {
  const Route r = loop_route(sim::load_world("room"), 0.25);
  // The room's loop: an ellipse of half-axes about 4 m and 2 m (19.4 m round), or a smaller one.
  EXPECT_GT(r.lap_length_m, 8.0);
  EXPECT_LT(r.lap_length_m, 20.0);
  ASSERT_GT(r.lap.size(), 30u);
  EXPECT_EQ(r.lap.front(), r.start);
  double longest = 0.0;
  for (size_t i = 1; i <= r.lap.size(); ++i) {
    const Eigen::Vector4d& a = r.lap[i - 1];
    const Eigen::Vector4d& b = i < r.lap.size() ? r.lap[i] : r.start;  // round to the next lap
    longest = std::max(longest, (b.head<3>() - a.head<3>()).norm());
    EXPECT_LT(std::abs(wrap_angle(b[3] - a[3])), 0.3) << i;
  }
  EXPECT_LT(longest, 0.3);
  const auto path = laps(r, 50.0);
  const size_t n = static_cast<size_t>(std::ceil(50.0 / r.lap_length_m));
  ASSERT_EQ(path.size(), n * r.lap.size() + 1);
  EXPECT_EQ(path.back(), r.start);
  EXPECT_EQ(path[r.lap.size()], r.start);
}

}  // namespace
}  // namespace kestrel::soak
