#include "vo/variants.h"

#include <functional>
#include <stdexcept>

namespace kestrel::vo {
namespace {

Variant make(std::string name, std::string description, const std::function<void(VoOptions&)>& change) {
  Variant v{std::move(name), std::move(description), VoOptions{}};
  change(v.options);
  v.options.validate();
  return v;
}

std::vector<Variant> build() {
  std::vector<Variant> out;
  out.push_back(make("default", "kestrel (max-clique, rotation prior, 3 levels, bidir. ESM)", [](VoOptions&) {}));
  out.push_back(make("ransac", "RANSAC inliers", [](VoOptions& o) {
    o.inliers.method = InlierMethod::kRansac;
  }));
  out.push_back(make("preemptive-ransac", "preemptive RANSAC (500 hypotheses)", [](VoOptions& o) {
    o.inliers.method = InlierMethod::kPreemptiveRansac;
  }));
  out.push_back(make("no-rotation-prior", "no initial rotation", [](VoOptions& o) {
    o.rotation_prior.enabled = false;
  }));
  for (int levels : {1, 2, 4}) {
    out.push_back(make("levels-" + std::to_string(levels), "pyramid levels " + std::to_string(levels),
                       [levels](VoOptions& o) { o.pyramid.levels = levels; }));
  }
  out.push_back(make("gauss-newton", "bidir. Gauss-Newton", [](VoOptions& o) {
    o.refinement.solver = Solver::kGaussNewton;
  }));
  out.push_back(make("unidir-gauss-newton", "unidir. Gauss-Newton", [](VoOptions& o) {
    o.refinement.solver = Solver::kGaussNewton;
    o.refinement.bidirectional = false;
  }));
  out.push_back(make("unidir-esm", "unidir. ESM", [](VoOptions& o) { o.refinement.bidirectional = false; }));
  out.push_back(make("absolute-orientation", "absolute orientation only", [](VoOptions& o) {
    o.refinement.enabled = false;
  }));
  for (int w : {3, 5, 7, 11}) {
    out.push_back(make("window-" + std::to_string(w), "window " + std::to_string(w),
                       [w](VoOptions& o) { o.match.window_size = w; }));
  }
  out.push_back(make("no-subpixel", "no subpixel refinement", [](VoOptions& o) { o.match.subpixel = false; }));
  out.push_back(make("fixed-threshold-10", "fixed FAST threshold 10", [](VoOptions& o) {
    o.fast.adaptive = false;
    o.fast.threshold = 10;
  }));
  out.push_back(make("no-dense", "no dense point-to-plane term", [](VoOptions& o) { o.dense.enabled = false; }));
  out.push_back(make("no-bucketing", "no bucketing", [](VoOptions& o) { o.bucket.enabled = false; }));
  return out;
}

}  // namespace

const std::vector<Variant>& variants() {
  static const std::vector<Variant> all = build();
  return all;
}

const Variant& variant(const std::string& name) {
  std::string known;
  for (const Variant& v : variants()) {
    if (v.name == name) return v;
    known += (known.empty() ? "" : ", ") + v.name;
  }
  throw std::invalid_argument("unknown VO variant '" + name + "' (known: " + known + ")");
}

}  // namespace kestrel::vo
