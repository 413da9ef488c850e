// kestrel-vo-crossval: leave-one-sequence-out cross-validation of the odometry's parameters
// fitted to recorded data (vo/cross_validation.h). Each candidate value runs the odometry over
// every sequence (the other options at each folder's sensor profile, as kestrel-vo --tum); the
// value best on one sequence is scored on the others. Without --param, the kinect1 profile's
// fitted parameters over grids around their values (sensors/profiles/kinect1.yaml).

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/error.h"
#include "vo/cross_validation.h"
#include "vo/option_keys.h"
#include "vo/sequence_run.h"

namespace {

using namespace kestrel;

struct Parameter {
  std::string key;
  std::vector<std::string> values;
  vo::Objective objective;
};

// The kinect1 profile's values fitted to fr1_xyz and fr1_rpy (its timing, dense weight, near
// rule and covariance model), each over a grid that brackets the profile's value; the ones
// chosen for a balance of two figures, once for each.
std::vector<Parameter> kinect_parameters() {
  using vo::Objective;
  return {
      {"depth.rolling_shutter_readout_s", {"0", "0.0075", "0.015", "0.0225", "0.03"}, Objective::kAte},
      {"depth.time_offset_s", {"0", "-0.0075", "-0.015", "-0.025", "-0.035"}, Objective::kAte},
      {"depth.time_offset_s", {"0", "-0.0075", "-0.015", "-0.025", "-0.035"}, Objective::kRpeRotation},
      {"dense.weight", {"0.4", "1", "2", "3", "4"}, Objective::kAte},
      {"dense.weight", {"0.4", "1", "2", "3", "4"}, Objective::kVelocity},
      {"keyframe.min_inliers_to_keep_near", {"0", "75", "150", "225", "300"}, Objective::kAte},
      {"keyframe.floor_cap_fraction", {"0", "0.3", "0.5", "0.7"}, Objective::kAte},
      {"covariance.translation_floor_m", {"0.0005", "0.001", "0.002", "0.004"}, Objective::kNees},
      {"covariance.rotation_floor_rad", {"0.001", "0.002", "0.004", "0.008"}, Objective::kNees},
      {"covariance.translation_per_rad_m", {"0.05", "0.1", "0.2", "0.4"}, Objective::kNees},
      {"covariance.rotation_per_rad", {"0.04", "0.085", "0.17", "0.34"}, Objective::kNees},
  };
}

// KEY=V1,V2,...
Parameter parse_parameter(const std::string& text, vo::Objective objective) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw CLI::ValidationError("--param", "'" + text + "' is not KEY=V1,V2,...");
  Parameter p{text.substr(0, eq), {}, objective};
  std::string rest = text.substr(eq + 1);
  for (size_t start = 0;;) {
    const size_t comma = rest.find(',', start);
    const std::string v = rest.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    if (v.empty()) throw CLI::ValidationError("--param", "'" + text + "' has an empty value");
    p.values.push_back(v);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return p;
}

// The figure the objective ranks by (lower is better; NaN when not measured) and what is shown.
struct Measured {
  double score = std::nan("");
  std::string shown = "n/a";
};
Measured measure(const vo::RunFigures& f, vo::Objective objective) {
  if (!f.scored) return {};
  switch (objective) {
    case vo::Objective::kAte: return {f.ate_rmse_m, fmt::format("{:.3g}", 100.0 * f.ate_rmse_m)};
    case vo::Objective::kRpeRotation: return {f.rpe_rotation_degps, fmt::format("{:.3g}", f.rpe_rotation_degps)};
    case vo::Objective::kVelocity: return {f.velocity_error_mps, fmt::format("{:.3g}", f.velocity_error_mps)};
    case vo::Objective::kNees:
      if (f.nees_frames == 0 || !(f.mean_nees > 0.0)) return {};
      return {std::abs(std::log(f.mean_nees / 6.0)),
              fmt::format("{:.3g} ({:.1f} %)", f.mean_nees, 100.0 * f.nees_within_95)};
  }
  return {};
}
const char* shown_unit(vo::Objective objective) {
  switch (objective) {
    case vo::Objective::kAte: return "ATE cm";
    case vo::Objective::kRpeRotation: return "RPE rotation deg/s";
    case vo::Objective::kVelocity: return "velocity error m/s";
    case vo::Objective::kNees: return "mean NEES, 6 = consistent (% under the 95 % bound)";
  }
  return "";
}

// A folder as a path to compare: normalised, without a trailing separator.
std::filesystem::path folder_path(const std::string& folder) {
  std::filesystem::path p = std::filesystem::path(folder).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p;
}

std::string option_value(const vo::VoOptions& options, const std::string& key) {
  for (const std::string& line : vo::describe_options(options))
    if (line.rfind(key + " = ", 0) == 0) return line.substr(key.size() + 3);
  return "?";
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("vo-crossval",
               "Leave-one-sequence-out cross-validation of the odometry's parameters fitted to recorded data: each "
               "value chosen on one TUM sequence is scored on the others (Markdown). Without --param: the kinect1 "
               "profile's fitted parameters. Exit 1 when some value could not be scored on some sequence (the "
               "tables say n/a there).");
  std::vector<std::string> folders;
  std::vector<std::string> params;
  std::string objective_name = "ate";
  app.add_option("--tum", folders, "TUM RGB-D sequence folders with groundtruth.txt (two or more; repeat)")->required();
  app.add_option("--param", params, "KEY=V1,V2,...: a vo option (kestrel-vo --print-config keys) and the values to try");
  app.add_option("--objective", objective_name, "What --param values are fitted for: ate, rpe-rotation, velocity or nees")
      ->capture_default_str();
  return app.run(argc, argv, [&] {
    const std::optional<vo::Objective> objective = vo::objective_named(objective_name);
    if (!objective)
      throw CLI::ValidationError("--objective", "'" + objective_name + "' is not ate, rpe-rotation, velocity or nees");
    if (folders.size() < 2) throw CLI::ValidationError("--tum", "cross-validation needs two sequences or more");
    for (size_t a = 0; a < folders.size(); ++a)
      for (size_t b = a + 1; b < folders.size(); ++b)
        if (folder_path(folders[a]) == folder_path(folders[b]))
          throw CLI::ValidationError("--tum", folders[b] + " is given twice: a sequence cannot be held out from itself");
    if (params.empty() && app.count("--objective") > 0)
      throw CLI::ValidationError("--objective", "goes with --param (the kinect1 parameters have their own objectives)");
    std::vector<Parameter> parameters;
    for (const std::string& p : params) parameters.push_back(parse_parameter(p, *objective));
    if (parameters.empty()) parameters = kinect_parameters();
    // Every value is checked on every folder's options before anything runs.
    for (const Parameter& p : parameters)
      for (const std::string& folder : folders)
        for (const std::string& v : p.values) {
          vo::VoOptions o = vo::with_tum_sensor(folder, {});
          try {
            vo::set_option(o, p.key, v);
          } catch (const std::invalid_argument& e) {
            throw CLI::ValidationError("--param", e.what());
          }
        }

    std::vector<vo::LoadedSequence> sequences;
    std::vector<std::string> names;  // the folders' names, or the folders as given where two share one
    for (const std::string& folder : folders) {
      sequences.push_back(vo::load_tum_sequence(folder));
      if (sequences.back().ground_truth.empty()) throw InputError(folder + ": no groundtruth.txt to score against");
      // A folder the profile's own options estimate nothing on is bad input, not a bad value.
      vo::require_usable(vo::run_sequence(sequences.back().frames, vo::with_tum_sensor(folder, {})).results, folder);
      names.push_back(folder_path(folder).filename().string());
    }
    const std::vector<std::string> base = names;
    for (size_t s = 0; s < names.size(); ++s)
      if (std::count(base.begin(), base.end(), base[s]) > 1) names[s] = folders[s];
    std::cout << "Leave-one-sequence-out cross-validation over";
    for (size_t s = 0; s < sequences.size(); ++s)
      std::cout << (s ? ", " : " ") << names[s] << " (" << sequences[s].frames.size() << " frames)";
    std::cout << "; one parameter at a time, the others at each folder's profile; the value best on one sequence "
                 "scored on the others.\n\n";

    std::string folds_table = "| parameter | fitted for | profile's value |";
    for (const std::string& n : names) folds_table += " fitted on " + n + ": value, held-out score (best there) |";
    folds_table += "\n|---|---|---|";
    for (size_t s = 0; s < names.size(); ++s) folds_table += "---|";
    folds_table += "\n";
    std::string grids;
    int unmeasured = 0;
    for (const Parameter& p : parameters) {
      std::vector<vo::CandidateScores> table;
      std::vector<std::vector<std::string>> shown;
      for (const std::string& v : p.values) {
        vo::CandidateScores row{v, {}};
        shown.emplace_back();
        for (size_t s = 0; s < sequences.size(); ++s) {
          vo::VoOptions o = vo::with_tum_sensor(folders[s], {});
          vo::set_option(o, p.key, v);
          const vo::RunFigures f = vo::score(vo::run_sequence(sequences[s].frames, o), sequences[s].ground_truth);
          const Measured m = measure(f, p.objective);
          if (!std::isfinite(m.score)) {
            ++unmeasured;
            spdlog::warn("{} = {} on {}: {} not measured ({})", p.key, v, names[s], shown_unit(p.objective),
                         f.scored ? "the run has too few frames for it" : f.not_scored);
          }
          row.scores.push_back(m.score);
          shown.back().push_back(m.shown);
        }
        table.push_back(std::move(row));
      }
      const std::vector<vo::Fold> folds = vo::leave_one_out(table);
      // The profile's value of each folder (one, unless the folders take different profiles).
      std::vector<std::string> profile_values;
      for (const std::string& folder : folders) {
        const std::string v = option_value(vo::with_tum_sensor(folder, {}), p.key);
        if (std::find(profile_values.begin(), profile_values.end(), v) == profile_values.end()) profile_values.push_back(v);
      }
      std::string profile;
      for (const std::string& v : profile_values) profile += (profile.empty() ? "" : " / ") + v;
      folds_table += "| `" + p.key + "` | " + shown_unit(p.objective) + " | " + profile + " |";
      for (size_t s = 0; s < sequences.size(); ++s) {
        const auto fold = std::find_if(folds.begin(), folds.end(), [&](const vo::Fold& f) { return f.fitted_on == s; });
        if (fold == folds.end()) {
          folds_table += " not measured |";
          continue;
        }
        std::string cell = " " + fold->chosen + ":";
        for (size_t i = 0; i < fold->held_out.size(); ++i) {
          const size_t o = fold->held_out[i];
          const size_t best = fold->held_out_best_rows[i];
          cell += " " + shown[fold->chosen_row][o] + " on " + names[o] + " (" +
                  (best == vo::kNoRow ? std::string("n/a") : shown[best][o]) + ")";
        }
        folds_table += cell + " |";
      }
      folds_table += "\n";
      grids += "\n`" + p.key + "`, " + shown_unit(p.objective) + ":\n\n| value |";
      for (const std::string& n : names) grids += " " + n + " |";
      grids += "\n|---|";
      for (size_t s = 0; s < names.size(); ++s) grids += "---|";
      grids += "\n";
      for (size_t r = 0; r < table.size(); ++r) {
        grids += "| " + table[r].value + " |";
        for (size_t s = 0; s < sequences.size(); ++s) grids += " " + shown[r][s] + " |";
        grids += "\n";
      }
      std::cerr << "." << std::flush;  // progress, apart from the Markdown
    }
    std::cerr << "\n";
    std::cout << folds_table << "\nEvery value:\n" << grids;
    return unmeasured == 0 ? kExitOk : kExitFailure;
  });
}
