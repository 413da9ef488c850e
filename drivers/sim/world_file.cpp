#include "drivers/sim/world_file.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <sstream>
#include <string_view>
#include <vector>

#include "common/error.h"
#include "common/numbers.h"
#include "common/text.h"
#include "drivers/sim/world_builder.h"

namespace kestrel::sim {
namespace {

std::string format_metres(double m) {
  char text[32];
  std::snprintf(text, sizeof text, "%g m", m);
  return text;
}

// One statement: its fields and where it came from, with checked accessors.
class Statement {
 public:
  Statement(std::vector<std::string_view> fields, const std::string& source, int line)
      : fields_(std::move(fields)), source_(source), line_(line) {}

  std::string keyword() const { return std::string(fields_[0]); }
  size_t size() const { return fields_.size(); }
  std::string word(size_t i) const { return std::string(fields_.at(i)); }

  [[noreturn]] void fail(const std::string& what) const {
    throw InputError(at_line(source_, line_, what));
  }
  double number(size_t i, const char* what) const {
    if (i >= fields_.size()) fail(keyword() + ": missing " + what);
    const auto v = parse_double(fields_[i]);
    if (!v || !std::isfinite(*v)) fail(keyword() + ": " + what + " '" + word(i) + "' is not a finite number");
    return *v;
  }
  /// A position or length in metres, within the world's bounds on size (world_file.h).
  double coordinate(size_t i, const char* what) const {
    const double v = number(i, what);
    if (std::abs(v) > kMaxWorldCoordinate_m)
      fail(keyword() + ": " + what + " '" + word(i) + "' is beyond +-" + format_metres(kMaxWorldCoordinate_m) +
           " (a world spans at most " + format_metres(2 * kMaxWorldCoordinate_m) + ")");
    return v;
  }
  /// Positional fields 1..n must all be there, before any option.
  void need(size_t n, const char* usage) const {
    if (fields_.size() < n + 1) fail(keyword() + ": expected '" + usage + "'");
  }

 private:
  std::vector<std::string_view> fields_;
  const std::string& source_;
  int line_;
};

// Trailing "key value..." options after the positional fields.
struct Options {
  std::optional<double> texture, yaw_deg, thick, scale, contrast;
  std::optional<std::pair<double, double>> z;
  std::optional<Eigen::Vector3d> color;
  bool fit = false;
};

Options parse_options(const Statement& st, size_t first, const std::vector<std::string>& allowed) {
  Options o;
  auto allowed_here = [&](const std::string& k) {
    for (const auto& a : allowed)
      if (a == k) return true;
    return false;
  };
  for (size_t i = first; i < st.size();) {
    const std::string key = st.word(i);
    if (!allowed_here(key)) st.fail(st.keyword() + ": unexpected '" + key + "'");
    if (key == "fit") {
      o.fit = true;
      i += 1;
    } else if (key == "z") {
      o.z = std::make_pair(st.coordinate(i + 1, "z0"), st.coordinate(i + 2, "z1"));
      i += 3;
    } else if (key == "color") {
      o.color = Eigen::Vector3d(st.number(i + 1, "red"), st.number(i + 2, "green"), st.number(i + 3, "blue"));
      i += 4;
    } else {
      const double v = key == "thick" ? st.coordinate(i + 1, "thick") : st.number(i + 1, key.c_str());
      if (key == "texture") o.texture = v;
      if (key == "yaw") o.yaw_deg = v;
      if (key == "thick") o.thick = v;
      if (key == "scale") o.scale = v;
      if (key == "contrast") o.contrast = v;
      i += 2;
    }
  }
  if (o.texture && *o.texture < 0) st.fail(st.keyword() + ": texture must be >= 0");
  return o;
}

class Parser {
 public:
  explicit Parser(const std::string& source) : source_(source), builder_("unnamed") {
    builder_.set_source(source);
  }

  void statement(const Statement& st) {
    const std::string k = st.keyword();
    if (!header_seen_) {
      if (k != "kestrel-world" || st.size() != 2 || st.word(1) != "1")
        st.fail("expected the header 'kestrel-world 1'");
      header_seen_ = true;
      return;
    }
    try {
      dispatch(st, k);
    } catch (const std::invalid_argument& e) {  // geometry the builder cannot take
      st.fail(e.what());
    }
  }

  void dispatch(const Statement& st, const std::string& k) {
    if (k == "name") return name(st);
    if (k == "seed") return seed(st);
    if (k == "bounds") return bounds(st);
    if (k == "start") return start(st);
    if (k == "ambient") return ambient(st);
    if (k == "material") return material(st);
    if (k == "floor" || k == "ceiling") return horizontal(st, k == "floor");
    if (k == "wall") return wall(st);
    if (k == "panel") return panel(st);
    if (k == "box") return box(st);
    if (k == "light") return light(st);
    st.fail("unknown statement '" + k + "'");
  }

  World finish(int last_line, WorldParts parts) {
    if (!header_seen_) throw InputError(at_line(source_, std::max(1, last_line), "empty world (no 'kestrel-world 1' header)"));
    if (builder_.surface_count() == 0) throw InputError(at_line(source_, last_line, "the world has no surfaces"));
    return builder_.build(parts);
  }

 private:
  void name(const Statement& st) {
    if (st.size() != 2) st.fail("name: expected 'name <word>'");
    builder_.set_name(st.word(1));
  }
  void seed(const Statement& st) {
    if (st.size() != 2) st.fail("seed: expected 'seed <integer>'");
    const auto v = parse_int(st.word(1));
    if (!v || *v < 0) st.fail("seed: '" + st.word(1) + "' is not a non-negative integer");
    builder_.set_seed(static_cast<uint64_t>(*v));
  }
  void bounds(const Statement& st) {
    st.need(6, "bounds <x0> <y0> <z0> <x1> <y1> <z1>");
    if (st.size() != 7) st.fail("bounds: too many values");
    const Eigen::Vector3d lo(st.coordinate(1, "x0"), st.coordinate(2, "y0"), st.coordinate(3, "z0"));
    const Eigen::Vector3d hi(st.coordinate(4, "x1"), st.coordinate(5, "y1"), st.coordinate(6, "z1"));
    if (!(hi.array() > lo.array()).all()) st.fail("bounds: the second corner must exceed the first in x, y and z");
    bounds_ = Eigen::AlignedBox3d(lo, hi);
    builder_.set_bounds(*bounds_);
  }
  void start(const Statement& st) {
    st.need(4, "start <x> <y> <z> <yaw_deg>");
    if (st.size() != 5) st.fail("start: too many values");
    builder_.set_start({st.coordinate(1, "x"), st.coordinate(2, "y"), st.coordinate(3, "z"), st.number(4, "yaw") * kDegree});
  }
  void ambient(const Statement& st) {
    if (st.size() != 2) st.fail("ambient: expected 'ambient <share in [0, 1]>'");
    const double a = st.number(1, "share");
    if (a < 0 || a > 1) st.fail("ambient: share must be in [0, 1]");
    lighting_.ambient = a;
    builder_.set_lighting(lighting_);
  }
  void material(const Statement& st) {
    st.need(2, "material <name> <pattern> [color r g b] [scale s] [contrast c] [fit]");
    MaterialSpec spec;
    spec.name = st.word(1);
    spec.pattern = st.word(2);
    if (!is_pattern(spec.pattern)) st.fail("material: unknown pattern '" + spec.pattern + "'");
    if (builder_.material_index(spec.name) >= 0) st.fail("material '" + spec.name + "' is defined twice");
    const Options o = parse_options(st, 3, {"color", "scale", "contrast", "fit"});
    if (o.color) {
      if (o.color->minCoeff() < 0 || o.color->maxCoeff() > 1) st.fail("material: colour values must be in [0, 1]");
      spec.color = *o.color;
    }
    if (o.scale) {
      if (*o.scale <= 0) st.fail("material: scale must be > 0");
      spec.scale = *o.scale;
    }
    if (o.contrast) {
      if (*o.contrast < 0) st.fail("material: contrast must be >= 0");
      spec.contrast = *o.contrast;
    }
    spec.fit = o.fit;
    builder_.add_material(spec);
  }
  int material_of(const Statement& st) const {
    const int m = builder_.material_index(st.word(1));
    if (m < 0) st.fail(st.keyword() + ": no material called '" + st.word(1) + "' (define it with 'material' first)");
    return m;
  }
  void horizontal(const Statement& st, bool is_floor) {
    st.need(6, is_floor ? "floor <material> <x0> <y0> <x1> <y1> <z>" : "ceiling <material> <x0> <y0> <x1> <y1> <z>");
    const int m = material_of(st);
    const Eigen::Vector2d lo(st.coordinate(2, "x0"), st.coordinate(3, "y0")), hi(st.coordinate(4, "x1"), st.coordinate(5, "y1"));
    if (!(hi.array() > lo.array()).all()) st.fail(st.keyword() + ": the second corner must exceed the first");
    const double z = st.coordinate(6, "z");
    const Options o = parse_options(st, 7, {"texture"});
    const Eigen::AlignedBox2d area(lo, hi);
    if (is_floor) builder_.add_floor(m, area, z, o.texture.value_or(1.0));
    else builder_.add_ceiling(m, area, z, o.texture.value_or(1.0));
  }
  std::pair<double, double> heights(const Statement& st, const Options& o) const {
    if (o.z) {
      if (!(o.z->second > o.z->first)) st.fail(st.keyword() + ": z1 must exceed z0");
      return *o.z;
    }
    if (!bounds_) st.fail(st.keyword() + ": give 'z <z0> <z1>' or a 'bounds' line before it");
    return {bounds_->min().z(), bounds_->max().z()};
  }
  void wall(const Statement& st) {
    st.need(5, "wall <material> <x0> <y0> <x1> <y1> [z z0 z1] [thick t] [texture d]");
    const int m = material_of(st);
    const Eigen::Vector2d a(st.coordinate(2, "x0"), st.coordinate(3, "y0")), b(st.coordinate(4, "x1"), st.coordinate(5, "y1"));
    if ((b - a).norm() < 1e-6) st.fail("wall: its two ends coincide");
    const Options o = parse_options(st, 6, {"z", "thick", "texture"});
    const auto [z0, z1] = heights(st, o);
    if (o.thick && *o.thick <= 0) st.fail("wall: thick must be > 0");
    if (o.thick) builder_.add_slab(m, a, b, z0, z1, *o.thick, o.texture.value_or(1.0));
    else builder_.add_wall(m, a, b, z0, z1, o.texture.value_or(1.0));
  }
  void panel(const Statement& st) {
    st.need(7, "panel <material> <x0> <y0> <x1> <y1> <z0> <z1> [texture d]");
    const int m = material_of(st);
    const Eigen::Vector2d a(st.coordinate(2, "x0"), st.coordinate(3, "y0")), b(st.coordinate(4, "x1"), st.coordinate(5, "y1"));
    const double z0 = st.coordinate(6, "z0"), z1 = st.coordinate(7, "z1");
    if ((b - a).norm() < 1e-6) st.fail("panel: its two ends coincide");
    if (!(z1 > z0)) st.fail("panel: z1 must exceed z0");
    const Options o = parse_options(st, 8, {"texture"});
    builder_.add_wall(m, a, b, z0, z1, o.texture.value_or(1.0), SurfaceKind::kPanel);
  }
  void box(const Statement& st) {
    st.need(7, "box <material> <x0> <y0> <z0> <x1> <y1> <z1> [yaw deg] [texture d]");
    const int m = material_of(st);
    const Eigen::Vector3d lo(st.coordinate(2, "x0"), st.coordinate(3, "y0"), st.coordinate(4, "z0"));
    const Eigen::Vector3d hi(st.coordinate(5, "x1"), st.coordinate(6, "y1"), st.coordinate(7, "z1"));
    if (!(hi.array() > lo.array()).all()) st.fail("box: the second corner must exceed the first in x, y and z");
    const Options o = parse_options(st, 8, {"yaw", "texture"});
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = 0.5 * (lo + hi);
    T.linear() = Eigen::AngleAxisd(o.yaw_deg.value_or(0.0) * kDegree, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    builder_.add_box(m, T, 0.5 * (hi - lo), o.texture.value_or(1.0));
  }
  void light(const Statement& st) {
    st.need(3, "light <x> <y> <z> [power]");
    if (st.size() > 5) st.fail("light: too many values");
    const double power = st.size() == 5 ? st.number(4, "power") : 1.0;
    if (power <= 0) st.fail("light: power must be > 0");
    builder_.add_light({{st.coordinate(1, "x"), st.coordinate(2, "y"), st.coordinate(3, "z")}, power});
  }

  const std::string& source_;
  WorldBuilder builder_;
  LightingOptions lighting_;
  std::optional<Eigen::AlignedBox3d> bounds_;
  bool header_seen_ = false;
};

}  // namespace

World parse_world(const std::string& text, const std::string& source, WorldParts parts) {
  Parser parser(source);
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    std::string_view view(line);
    if (const size_t hash = view.find('#'); hash != std::string_view::npos) view = view.substr(0, hash);
    if (is_comment_or_blank(view)) continue;
    parser.statement(Statement(split_fields(view), source, line_no));
  }
  return parser.finish(line_no, parts);
}

World load_world_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open world file");
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path + ": read error");
  return parse_world(text.str(), path);
}

}  // namespace kestrel::sim
