#include "tools/soak/soak.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>

#include "common/json_number.h"

namespace kestrel::soak {
namespace {

std::string number(double v, int decimals) { return std::isfinite(v) ? fmt::format("{:.{}f}", v, decimals) : "—"; }
std::string csv_number(double v, int decimals) { return std::isfinite(v) ? fmt::format("{:.{}f}", v, decimals) : ""; }
std::string minutes(double s) { return number(s / 60.0, 1) + " min"; }

// The samples of each process, in the order the processes were first sampled.
std::vector<std::pair<std::string, std::vector<const ProcessSample*>>> by_process(
    const std::vector<ProcessSample>& samples) {
  std::vector<std::pair<std::string, std::vector<const ProcessSample*>>> out;
  std::map<std::string, size_t> index;
  for (const ProcessSample& s : samples) {
    auto [it, added] = index.emplace(s.process, out.size());
    if (added) out.push_back({s.process, {}});
    out[it->second].second.push_back(&s);
  }
  return out;
}

ProcessSummary summarise_process(const std::string& name, const std::vector<const ProcessSample*>& ss,
                                 const Criteria& c, double reached_s) {
  ProcessSummary p;
  p.process = name;
  p.samples = ss.size();
  if (ss.empty()) return p;
  const ProcessSample& last = *ss.back();
  p.end_at_s = last.sim_s;
  p.rss_end_mb = last.rss_mb;
  p.anon_end_mb = last.anon_mb;
  p.rss_peak_mb = 0.0;
  for (const ProcessSample* s : ss) p.rss_peak_mb = std::max(p.rss_peak_mb, s->rss_mb);
  const auto warm = std::find_if(ss.begin(), ss.end(), [&](const ProcessSample* s) { return s->sim_s >= c.warmup_s; });
  if (warm != ss.end()) {
    p.warmup_at_s = (*warm)->sim_s;
    p.rss_warmup_mb = (*warm)->rss_mb;
    p.anon_warmup_mb = (*warm)->anon_mb;
    // The CPU per frame over the first and the last third of [warm-up, end], and all of it.
    const double third = (last.sim_s - p.warmup_at_s) / 3.0;
    const auto early_end = std::find_if(warm, ss.end(), [&](const ProcessSample* s) {
      return s->sim_s >= p.warmup_at_s + third;
    });
    if (early_end != ss.end()) p.cpu_ms_per_frame_early = cpu_ms_per_frame(**warm, **early_end);
    const auto late_begin = std::find_if(warm, ss.end(), [&](const ProcessSample* s) {
      return s->sim_s >= last.sim_s - third;
    });
    if (late_begin != ss.end()) p.cpu_ms_per_frame_late = cpu_ms_per_frame(**late_begin, last);
    p.cpu_ms_per_frame_all = cpu_ms_per_frame(**warm, last);
  }
  // The growth over the last two thirds of the run (never into the warm-up).
  p.fit_from_s = std::max(c.warmup_s, reached_s / 3.0);
  std::vector<double> t, rss, anon;
  for (const ProcessSample* s : ss) {
    if (s->sim_s < p.fit_from_s) continue;
    t.push_back(s->sim_s);
    rss.push_back(s->rss_mb);
    anon.push_back(s->anon_mb);
  }
  p.fit_samples = t.size();
  if (p.fit_samples >= 3) {
    p.growth_mb_per_10min = 600.0 * fit_line(t, rss).slope;
    p.anon_growth_mb_per_10min = 600.0 * fit_line(t, anon).slope;
  }
  if (!std::isfinite(p.growth_mb_per_10min)) {
    p.verdict = "too short";
  } else {
    p.verdict = p.growth_mb_per_10min < c.flat_mb_per_10min ? "flat" : "grows";
  }
  return p;
}

}  // namespace

Line fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  Line l;
  const size_t n = std::min(x.size(), y.size());
  if (n == 0) return l;
  double mx = 0.0, my = 0.0;
  for (size_t i = 0; i < n; ++i) mx += x[i], my += y[i];
  mx /= static_cast<double>(n);
  my /= static_cast<double>(n);
  double sxx = 0.0, sxy = 0.0;
  for (size_t i = 0; i < n; ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  if (!(sxx > 0.0)) return l;
  l.slope = sxy / sxx;
  l.intercept = my - l.slope * mx;
  return l;
}

double cpu_ms_per_frame(const ProcessSample& from, const ProcessSample& to) {
  const int64_t frames = to.frames - from.frames;
  if (frames <= 0 || to.pid != from.pid) return kNaN;
  return 1e3 * (to.cpu_s - from.cpu_s) / static_cast<double>(frames);
}

bool Summary::usable() const {
  if (!(sim_s > 0.0) || processes.empty()) return false;
  return std::all_of(processes.begin(), processes.end(), [](const ProcessSummary& p) { return p.samples >= 2; });
}

bool Summary::all_flat() const {
  return !processes.empty() &&
         std::all_of(processes.begin(), processes.end(), [](const ProcessSummary& p) { return p.verdict == "flat"; });
}

Summary summarise(const std::vector<ProcessSample>& samples, const std::vector<ProgressSample>& progress,
                  const Criteria& criteria, const std::vector<std::pair<std::string, std::string>>& died) {
  Summary s;
  s.criteria = criteria;
  for (const ProcessSample& p : samples) {
    s.sim_s = std::max(s.sim_s, p.sim_s);
    s.wall_s = std::max(s.wall_s, p.wall_s);
  }
  for (const ProgressSample& p : progress) {
    s.sim_s = std::max(s.sim_s, p.sim_s);
    s.wall_s = std::max(s.wall_s, p.wall_s);
  }
  if (!progress.empty()) {
    const ProgressSample& last = progress.back();
    s.frames = last.frames;
    s.vo_failures = last.vo_failures;
    s.distance_m = last.distance_m;
    s.keyframes = last.keyframes;
    s.corrections = last.corrections;
    const auto warm = std::find_if(progress.begin(), progress.end(),
                                   [&](const ProgressSample& p) { return p.sim_s >= criteria.warmup_s; });
    if (warm != progress.end() && last.frames > warm->frames)
      s.wall_ms_per_frame = 1e3 * (last.wall_s - warm->wall_s) / static_cast<double>(last.frames - warm->frames);
    // The VO's own timing, weighted by the frames of each round.
    double sum = 0.0, frames = 0.0;
    for (auto it = warm; it != progress.end(); ++it) {
      if (it == progress.begin() || !std::isfinite(it->vo_elapsed_ms)) continue;
      const double n = static_cast<double>(it->frames - std::prev(it)->frames);
      sum += n * it->vo_elapsed_ms;
      frames += n;
    }
    if (frames > 0.0) s.vo_elapsed_ms = sum / frames;
  }
  for (const auto& [name, ss] : by_process(samples)) s.processes.push_back(summarise_process(name, ss, criteria, s.sim_s));
  for (const auto& [name, how] : died) {
    auto it = std::find_if(s.processes.begin(), s.processes.end(), [&process = name](const ProcessSummary& p) { return p.process == process; });
    if (it == s.processes.end()) {
      s.processes.push_back({});
      it = std::prev(s.processes.end());
      it->process = name;
    }
    it->died = true;
    it->died_how = how;
    it->verdict = "died";
  }
  return s;
}

std::string samples_csv(const std::vector<ProcessSample>& samples) {
  std::string out = "wall_s,sim_s,process,pid,rss_MB,anon_MB,cpu_s,frames,cpu_ms_per_frame\n";
  std::map<std::string, const ProcessSample*> previous;
  for (const ProcessSample& s : samples) {
    const ProcessSample*& before = previous[s.process];
    const double per_frame = before ? cpu_ms_per_frame(*before, s) : kNaN;
    before = &s;
    out += fmt::format("{:.3f},{:.3f},{},{},{:.3f},{:.3f},{:.3f},{},{}\n", s.wall_s, s.sim_s, s.process, s.pid, s.rss_mb,
                       s.anon_mb, s.cpu_s, s.frames, csv_number(per_frame, 4));
  }
  return out;
}

std::string progress_csv(const std::vector<ProgressSample>& progress) {
  std::string out = "wall_s,sim_s,frames,vo_failures,vo_elapsed_ms,wall_ms_per_frame,distance_m,keyframes,corrections\n";
  for (size_t i = 0; i < progress.size(); ++i) {
    const ProgressSample& p = progress[i];
    double wall_per_frame = kNaN;
    if (i > 0 && p.frames > progress[i - 1].frames)
      wall_per_frame = 1e3 * (p.wall_s - progress[i - 1].wall_s) / static_cast<double>(p.frames - progress[i - 1].frames);
    out += fmt::format("{:.3f},{:.3f},{},{},{},{},{:.3f},{},{}\n", p.wall_s, p.sim_s, p.frames, p.vo_failures,
                       csv_number(p.vo_elapsed_ms, 4),
                       csv_number(wall_per_frame, 4), p.distance_m, p.keyframes, p.corrections);
  }
  return out;
}

std::string markdown(const Summary& s, const std::string& heading, const std::string& failure) {
  const Criteria& c = s.criteria;
  std::string out = "# Soak (kestrel soak)\n\n" + heading + "\n\n";
  out += fmt::format(
      "Flown: {} of simulated flight (of {} asked) in {} of wall time; {} frames ({} without a VO motion), {:.0f} m "
      "by the truth, {} keyframes in SLAM's last graph, {} SLAM corrections. Lock-step pace after the warm-up: {} ms "
      "of wall time per frame for the whole system; the VO's own time {} ms per frame.\n\n",
      minutes(s.sim_s), minutes(c.run_s), minutes(s.wall_s), s.frames, s.vo_failures, s.distance_m, s.keyframes,
      s.corrections,
      number(s.wall_ms_per_frame, 1), number(s.vo_elapsed_ms, 2));
  if (!failure.empty()) out += "**The flight stopped early:** " + failure + "\n\n";
  out += fmt::format(
      "Resident memory (VmRSS, MB = 10^6 bytes) at the first sample from {} of simulated flight (the warm-up) and at "
      "the end; its growth is the slope of a least-squares line over the samples of the last two thirds of the run "
      "(from {}), per 10 simulated minutes: **flat** when below {} MB per 10 min. The heap is the anonymous part "
      "(RssAnon), where a leak shows. CPU per frame: the process's CPU time (user + system) per camera frame over "
      "the first and the last third of the time after the warm-up.\n\n",
      minutes(c.warmup_s), minutes(s.processes.empty() ? kNaN : s.processes.front().fit_from_s),
      number(c.flat_mb_per_10min, 1));
  out += "| process | RSS after warm-up | RSS at end | peak | growth / 10 min | heap: warm-up → end, growth / 10 min "
         "| CPU per frame, early → late | verdict |\n";
  out += "|---|---|---|---|---|---|---|---|\n";
  for (const ProcessSummary& p : s.processes) {
    out += fmt::format("| {} | {} MB | {} MB | {} MB | {} MB | {} → {} MB, {} MB | {} → {} ms | {} |\n", p.process,
                       number(p.rss_warmup_mb, 1), number(p.rss_end_mb, 1), number(p.rss_peak_mb, 1),
                       number(p.growth_mb_per_10min, 2), number(p.anon_warmup_mb, 1), number(p.anon_end_mb, 1),
                       number(p.anon_growth_mb_per_10min, 2), number(p.cpu_ms_per_frame_early, 2),
                       number(p.cpu_ms_per_frame_late, 2), p.died ? "died: " + p.died_how : p.verdict);
  }
  out += "\nEvery sample: `samples.csv` (per process) and `progress.csv` (the flight); the picture: `soak.png`.\n";
  return out;
}

nlohmann::json to_json(const Summary& s, const std::string& failure) {
  nlohmann::json j;
  j["criteria"] = {{"run_s", s.criteria.run_s},
                   {"warmup_s", s.criteria.warmup_s},
                   {"flat_mb_per_10min", s.criteria.flat_mb_per_10min}};
  j["sim_s"] = s.sim_s;
  j["wall_s"] = s.wall_s;
  j["frames"] = s.frames;
  j["vo_failures"] = s.vo_failures;
  j["distance_m"] = s.distance_m;
  j["keyframes"] = s.keyframes;
  j["corrections"] = s.corrections;
  j["wall_ms_per_frame"] = finite_or_null(s.wall_ms_per_frame);
  j["vo_elapsed_ms"] = finite_or_null(s.vo_elapsed_ms);
  j["failure"] = failure;
  j["usable"] = s.usable();
  j["all_flat"] = s.all_flat();
  nlohmann::json processes = nlohmann::json::array();
  for (const ProcessSummary& p : s.processes) {
    processes.push_back({{"process", p.process},
                         {"samples", p.samples},
                         {"died", p.died},
                         {"died_how", p.died_how},
                         {"warmup_at_s", finite_or_null(p.warmup_at_s)},
                         {"rss_warmup_mb", finite_or_null(p.rss_warmup_mb)},
                         {"end_at_s", finite_or_null(p.end_at_s)},
                         {"rss_end_mb", finite_or_null(p.rss_end_mb)},
                         {"rss_peak_mb", finite_or_null(p.rss_peak_mb)},
                         {"anon_warmup_mb", finite_or_null(p.anon_warmup_mb)},
                         {"anon_end_mb", finite_or_null(p.anon_end_mb)},
                         {"fit_from_s", finite_or_null(p.fit_from_s)},
                         {"fit_samples", p.fit_samples},
                         {"growth_mb_per_10min", finite_or_null(p.growth_mb_per_10min)},
                         {"anon_growth_mb_per_10min", finite_or_null(p.anon_growth_mb_per_10min)},
                         {"cpu_ms_per_frame_early", finite_or_null(p.cpu_ms_per_frame_early)},
                         {"cpu_ms_per_frame_late", finite_or_null(p.cpu_ms_per_frame_late)},
                         {"cpu_ms_per_frame", finite_or_null(p.cpu_ms_per_frame_all)},
                         {"verdict", p.verdict}});
  }
  j["processes"] = processes;
  return j;
}

}  // namespace kestrel::soak
