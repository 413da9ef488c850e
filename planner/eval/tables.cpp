// The experiment tables. Means are over successful trials; times are medians.
#include "planner/eval/tables.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>

#include "common/gaussian/information.h"
#include "planner/grid_environment.h"
#include "planner/samplers.h"

namespace kestrel::planner::eval {
namespace {

// "%.Nf" (or "%.Ne" with scientific) without a non-literal format string.
std::string fmt(const char* f, double v) {
  std::ostringstream s;
  const int digits = f[2] - '0';
  if (f[3] == 'e') s << std::scientific;
  else s << std::fixed;
  s << std::setprecision(digits) << v;
  return s.str();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

struct Summary {
  int trials = 0, found = 0, successes = 0;
  std::vector<double> goal_traces, build_s, search_s, lengths;
  std::vector<double> trial_traces;  ///< per trial in run order; NaN where it failed
  double success_pct() const { return trials ? 100.0 * successes / trials : 0.0; }
  double found_pct() const { return trials ? 100.0 * found / trials : 0.0; }
  double mean_trace() const {
    return goal_traces.empty() ? 0.0 : std::accumulate(goal_traces.begin(), goal_traces.end(), 0.0) / goal_traces.size();
  }
  /// Standard error of mean_trace() (0 with fewer than two successes).
  double sem_trace() const {
    const size_t n = goal_traces.size();
    if (n < 2) return 0.0;
    const double m = mean_trace();
    double ss = 0.0;
    for (double v : goal_traces) ss += (v - m) * (v - m);
    return std::sqrt(ss / static_cast<double>(n - 1) / static_cast<double>(n));
  }
  double mean_length() const {
    return lengths.empty() ? 0.0 : std::accumulate(lengths.begin(), lengths.end(), 0.0) / lengths.size();
  }
};

// `first_pair`: the index of pairs[0] among the experiment's pairs, so that a path gets the same
// seeds whether it runs alone (Table 4) or with the others (Table 5).
Summary run_many(const Scenario& sc, const Setting& s, const Pairs& pairs, const ExperimentOptions& o,
                 size_t first_pair = 0) {
  Summary sum;
  for (size_t p = 0; p < pairs.size(); ++p)
    for (int t = 0; t < o.trials; ++t) {
      // The same seed per (pair, trial) for every setting: samplers differ, not luck.
      const Trial r = run_trial(sc, s, pairs[p].first, pairs[p].second, o.seed * 1000003ull + (first_pair + p) * 1009ull + t);
      ++sum.trials;
      sum.build_s.push_back(r.build_s);
      sum.search_s.push_back(r.search_s);
      sum.found += r.found;
      sum.trial_traces.push_back(r.success ? r.goal_trace : std::numeric_limits<double>::quiet_NaN());
      if (!r.success) continue;
      ++sum.successes;
      sum.goal_traces.push_back(r.goal_trace);
      sum.lengths.push_back(r.length_m);
    }
  return sum;
}

}  // namespace

std::string table3_weight_cost(uint64_t seed) {
  // A wall of features straight ahead, all visible to an all-round sensor: the weight's cost
  // per sample for 90 / 300 / 500 scalar measurements (30 / 100 / 167 features).
  std::ostringstream out;
  out << "| measurements | tr(M) ms/sample | I(x) ms/sample | paper tr(M) | paper I(x) |\n|---|---|---|---|---|\n";
  const char* paper[3][2] = {{"0.731", "0.0743"}, {"2.84", "0.187"}, {"7.23", "0.289"}};
  int row = 0;
  for (int features : {30, 100, 167}) {
    OccupancyGrid g = make_grid(80, 80, 0.1, 0.05, 0.05);
    GridEnvironment env(g, 0.0, 3.0);
    Rng rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Feature> fs;
    for (int i = 0; i < features; ++i) {
      Feature f;
      f.position = {6.0, 4.0 + 2.0 * u(rng), 1.0 + 0.8 * u(rng)};
      f.normal = {-1.0, 0.0, 0.0};
      fs.push_back(f);
    }
    env.set_features(fs);
    const FeatureSensor sensor(env, FeatureSensorOptions::planar_laser(5.0));
    const Config q(3.0, 4.0, 1.0, 0.0);
    const int reps = 200;
    double sink = 0.0;
    auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < reps; ++i) sink += sensor.information(q).trace();
    const double ekf_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / reps;
    t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < reps; ++i) sink += sensor.ukf_information_gain(q, Mat4::Identity());
    const double ukf_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / reps;
    out << "| " << 3 * features << " | " << fmt("%.4f", ekf_ms) << " | " << fmt("%.4f", ukf_ms) << " | "
        << paper[row][0] << " | " << paper[row][1] << " |\n";
    ++row;
    if (!(sink == sink)) out << "(NaN)\n";
  }
  return out.str();
}

std::string table4_samplers(const Scenario& sc, const Pairs& pairs, const ExperimentOptions& o) {
  // The paper's rows (success % · goal tr(Sigma), paths 1-5), by sampler; it has no UKF row.
  static const std::map<std::string, std::array<const char*, 5>> paper = {
      {"uniform", {"100 · 17.87", "96.6 · 22.60", "100 · 2.22", "100 · 19.11", "100 · 1.48"}},
      {"su", {"100 · 12.38", "96.6 · 11.36", "100 · 1.99", "100 · 12.39", "100 · 1.39"}},
      {"gaussian", {"96.6 · 23.89", "96.6 · 17.89", "100 · 17.2", "93.1 · 22.16", "89.7 · 1.41"}},
      {"bridge", {"100 · 21.58", "3.5 · 13.48", "17.2 · 2.33", "100 · 21.32", "13.8 · 1.36"}}};
  const std::vector<std::string>& names = sampler_names();
  std::ostringstream out;
  out << "| sampler |";
  for (size_t p = 0; p < pairs.size(); ++p) out << " path " << p + 1 << " |";
  out << " paper (paths 1-5) |\n|---|";
  for (size_t p = 0; p <= pairs.size(); ++p) out << "---|";
  out << "\n";
  std::map<std::string, std::vector<Summary>> all;
  for (const std::string& name : names) {
    out << "| " << name << " |";
    for (size_t p = 0; p < pairs.size(); ++p) {
      all[name].push_back(run_many(sc, Setting{"brm", name, o.samples}, Pairs{pairs[p]}, o, p));
      const Summary& s = all[name].back();
      out << " " << fmt("%.1f", s.success_pct()) << " · " << fmt("%.2f", s.mean_trace()) << " ± "
          << fmt("%.2f", s.sem_trace()) << " |";
    }
    out << " ";
    const auto row = paper.find(name);
    if (row != paper.end())
      for (size_t p = 0; p < row->second.size(); ++p) out << row->second[p] << (p + 1 < row->second.size() ? "; " : "");
    else
      out << "—";
    out << " |\n";
  }
  // The target "SU no worse than uniform, Gaussian and bridge on each path": SU (EKF) is worse
  // than another sampler on a path when its success rate is lower, or its mean goal tr(Sigma)
  // higher, by more than two standard errors of the difference (binomial for the rates).
  out << "\nSU (EKF) against the other samplers, per path:";
  for (size_t p = 0; p < pairs.size(); ++p) {
    const Summary& su = all.at("su")[p];
    std::string worse;
    for (const char* other_name : {"uniform", "gaussian", "bridge"}) {
      const Summary& other = all.at(other_name)[p];
      const double se = std::hypot(su.sem_trace(), other.sem_trace());
      const double p1 = su.success_pct() / 100.0, p2 = other.success_pct() / 100.0;
      const double se_rate = std::sqrt(p1 * (1 - p1) / su.trials + p2 * (1 - p2) / other.trials);
      // Traces are compared only when both have successes (a mean over none is no value).
      const bool traces = su.successes > 0 && other.successes > 0;
      if (p1 < p2 - 2.0 * se_rate - 1e-12 || (traces && su.mean_trace() > other.mean_trace() + 2.0 * se))
        worse += std::string(worse.empty() ? "" : ", ") + other_name;
    }
    out << " path " << p + 1 << ": " << (worse.empty() ? "no worse" : "worse than " + worse) << ";";
  }
  out << "\n";
  return out.str();
}

std::string table5_planners(const Scenario& sc, const Pairs& pairs, const ExperimentOptions& o) {
  struct Row {
    const char* planner;
    const char* sampler;
    const char* paper;
  };
  const Row rows[] = {{"prm", "uniform", "56.38 · 0.79 · 0.15"},   {"brm", "uniform", "19.11 · 110.75 · 0.38"},
                      {"brm", "su", "12.31 · 323.12 · 0.55"},      {"brm", "su-ukf", "—"},
                      {"brm", "gaussian", "22.82 · 88.14 · 0.21"}, {"brm", "bridge", "21.92 · 178.58 · 0.30"},
                      {"brm-dominance", "su", "—"}};
  std::vector<Summary> runs;
  for (const Row& r : rows) runs.push_back(run_many(sc, Setting{r.planner, r.sampler, o.samples}, pairs, o));
  // Each setting's mean is over its own successes, which differ from row to row; the trials a
  // setting and PRM both solved (same seeds per pair and trial) compare like with like.
  const Summary& prm = runs.front();
  const auto ratio_to_prm = [&](const Summary& s, int* n) {
    double mine = 0.0, theirs = 0.0;
    *n = 0;
    for (size_t t = 0; t < s.trial_traces.size(); ++t)
      if (!std::isnan(s.trial_traces[t]) && !std::isnan(prm.trial_traces[t])) {
        mine += s.trial_traces[t];
        theirs += prm.trial_traces[t];
        ++*n;
      }
    return *n > 0 ? mine / theirs : std::numeric_limits<double>::quiet_NaN();
  };
  std::ostringstream out;
  out << "| planner | sampler | path found % | success % | goal tr(Σ) | ÷ PRM's, trials both solved (n) | length m | build s (median) | search ms (median) | paper tr · build s · search s |\n"
         "|---|---|---|---|---|---|---|---|---|---|\n";
  for (size_t i = 0; i < runs.size(); ++i) {
    const Row& r = rows[i];
    const Summary& s = runs[i];
    int n = 0;
    const double ratio = ratio_to_prm(s, &n);
    out << "| " << r.planner << " | " << r.sampler << " | " << fmt("%.1f", s.found_pct()) << " | " << fmt("%.1f", s.success_pct()) << " | "
        << fmt("%.2f", s.mean_trace()) << " | " << fmt("%.2f", ratio) << " (" << n << ") | " << fmt("%.1f", s.mean_length())
        << " | " << fmt("%.3f", median(s.build_s)) << " | " << fmt("%.3f", 1e3 * median(s.search_s)) << " | " << r.paper
        << " |\n";
  }
  return out.str();
}

std::string fig7_ukf_transfer(const Scenario& sc, const ExperimentOptions& o) {
  // The one-step transfer built from the UKF's M (eq. 27, at the sampler's constant prior)
  // against a full UKF update from other priors: relative tr(Sigma) error.
  const ConfigurationSpace space(*sc.env, sc.space);
  const FeatureSensor sensor(*sc.env, sc.sensor);
  Rng rng(o.seed);
  std::vector<double> errors;
  std::normal_distribution<double> n(0.0, 1.0);
  int poses = 0;
  while (poses < 70) {
    const Config q = space.uniform(rng);
    if (!space.is_valid(q) || sensor.visible(q).empty()) continue;
    ++poses;
    const Mat4 M = sensor.ukf_information(q, sc.ukf_prior);
    for (int k = 0; k < 100; ++k) {
      Mat4 A;
      for (int i = 0; i < 16; ++i) A(i) = n(rng);
      const Mat4 prior = 0.02 * A * A.transpose() + 0.02 * Mat4::Identity();  // tr about 0.4, as on paths
      const Mat4 transfer = gaussian::update_covariance(prior, M);
      const Mat4 full = gaussian::update_covariance(prior, sensor.ukf_information(q, prior));
      errors.push_back(std::abs(transfer.trace() - full.trace()) / full.trace());
    }
  }
  std::sort(errors.begin(), errors.end());
  std::ostringstream out;
  out << "| trials | median error % | 95th percentile % | max % | paper |\n|---|---|---|---|---|\n| "
      << errors.size() << " | " << fmt("%.3f", 100 * errors[errors.size() / 2]) << " | "
      << fmt("%.3f", 100 * errors[errors.size() * 95 / 100]) << " | " << fmt("%.3f", 100 * errors.back())
      << " | < 2 % (7000 trials, 100 priors) |\n";
  return out.str();
}

std::string fig12_sample_counts(const Scenario& sc, const Pairs& pairs, const ExperimentOptions& o,
                                const std::vector<int>& counts) {
  std::ostringstream out;
  out << "| samples | success % | goal tr(Σ) | build s (median) |\n|---|---|---|---|\n";
  for (int c : counts) {
    const Summary s = run_many(sc, Setting{"brm", "su", c}, pairs, o);
    out << "| " << c << " | " << fmt("%.1f", s.success_pct()) << " | " << fmt("%.2e", s.mean_trace()) << " | "
        << fmt("%.3f", median(s.build_s)) << " |\n";
  }
  return out.str();
}

std::string laser_experiment(const Scenario& sc, const Pairs& pairs, const ExperimentOptions& o,
                             double short_range_m, double long_range_m, double bound) {
  // Shortest paths under tr(Sigma) < bound, planned for each range on the same samples; the
  // long-range plan is then flown with the short-range sensor. Twice on the same roadmaps:
  // the bound checked at nodes (the paper's Algorithm 1), then along every edge's steps.
  std::ostringstream rows[2];
  for (size_t p = 0; p < pairs.size(); ++p) {
    Scenario s_short = sc, s_long = sc;
    s_short.sensor = FeatureSensorOptions::planar_laser(short_range_m);
    s_long.sensor = FeatureSensorOptions::planar_laser(long_range_m);
    const ConfigurationSpace space(*sc.env, sc.space);
    const FeatureSensor f_short(*sc.env, s_short.sensor), f_long(*sc.env, s_long.sensor);
    const BeliefModel m_short(sc.motion, [&](const Config& q) { return f_short.information(q); });
    const BeliefModel m_long(sc.motion, [&](const Config& q) { return f_long.information(q); });
    auto roadmap = [&](const BeliefModel& m) {
      Rng rng(o.seed + p);
      auto sampler = make_uniform_sampler(space);
      RoadmapOptions ro = sc.roadmap;
      ro.samples = o.samples;
      return build_roadmap(space, *sampler, pairs[p].first, pairs[p].second, ro, &m, rng);
    };
    const Roadmap map_short = roadmap(m_short), map_long = roadmap(m_long);
    auto plan = [&](const Roadmap& map, const BeliefModel& m, bool along_edges) {
      BrmQuery q;
      q.start_covariance = sc.start_covariance;
      q.objective = BrmObjective::kShortestBounded;
      q.max_trace = bound;
      if (along_edges)
        q.edge_peak_trace = [&](int from, int to, const Mat4& sigma) {
          return peak_trace_along(m, map.node(from), map.node(to), sigma);
        };
      std::vector<Config> path;
      for (int n : belief_search(map, 0, 1, q).nodes) path.push_back(map.node(n));
      return path;
    };
    auto max_of = [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); };
    for (int along = 0; along < 2; ++along) {
      std::ostringstream& out = rows[along];
      const auto ps = plan(map_short, m_short, along), pl = plan(map_long, m_long, along);
      out << "| " << p + 1 << " | ";
      if (ps.empty()) out << "no path";
      else out << fmt("%.2f", path_length(ps)) << " · " << fmt("%.3f", max_of(fly(ps, m_short, sc.start_covariance)));
      out << " | ";
      if (pl.empty()) out << "no path | — |\n";
      else
        out << fmt("%.2f", path_length(pl)) << " · " << fmt("%.3f", max_of(fly(pl, m_long, sc.start_covariance)))
            << " | " << fmt("%.3f", max_of(fly(pl, m_short, sc.start_covariance))) << " |\n";
    }
  }
  std::ostringstream out;
  for (int along = 0; along < 2; ++along) {
    out << (along ? "\nBound checked along every edge (each step flown):\n\n"
                  : "Bound checked at nodes (the paper's Algorithm 1):\n\n")
        << "| path | plan for " << short_range_m << " m: length · max tr | plan for " << long_range_m
        << " m: length · max tr | long-range plan flown with " << short_range_m << " m: max tr |\n|---|---|---|---|\n"
        << rows[along].str();
  }
  return out.str();
}

std::string transfer_precision(const Scenario& sc, const Pairs& pairs, const ExperimentOptions& o) {
  // Every directed edge of BRM roadmaps: both transfers against step-by-step EKF.
  const ConfigurationSpace space(*sc.env, sc.space);
  const FeatureSensor sensor(*sc.env, sc.sensor);
  const BeliefModel model(sc.motion, [&](const Config& q) { return sensor.information(q); });
  std::vector<double> sym, sca;
  for (size_t p = 0; p < pairs.size(); ++p) {
    Rng rng(o.seed + p);
    auto sampler = make_uniform_sampler(space);
    RoadmapOptions ro = sc.roadmap;
    ro.samples = o.samples;
    const Roadmap map = build_roadmap(space, *sampler, pairs[p].first, pairs[p].second, ro, nullptr, rng);
    for (int a = 0; a < map.size(); ++a)
      for (const Edge& e : map.edges(a)) {
        const auto steps = model.steps(map.node(a), map.node(e.to));
        const Mat4 ref = propagate_ekf(sc.start_covariance, steps);
        const auto err = [&](const Mat4& s) { return std::abs(s.trace() - ref.trace()) / ref.trace(); };
        sym.push_back(err(SymplecticTransfer::from_steps(steps).apply(sc.start_covariance)));
        sca.push_back(err(ScatteringTransfer::from_steps(steps).apply(sc.start_covariance)));
      }
  }
  std::sort(sym.begin(), sym.end());
  std::sort(sca.begin(), sca.end());
  std::ostringstream out;
  out << "| transfer | edges | median rel. tr error | max rel. tr error |\n|---|---|---|---|\n";
  out << "| symplectic (paper) | " << sym.size() << " | " << fmt("%.2e", sym[sym.size() / 2]) << " | "
      << fmt("%.2e", sym.back()) << " |\n";
  out << "| scattering (star product) | " << sca.size() << " | " << fmt("%.2e", sca[sca.size() / 2]) << " | "
      << fmt("%.2e", sca.back()) << " |\n";
  return out.str();
}

}  // namespace kestrel::planner::eval
