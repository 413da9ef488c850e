#include "tools/soak/soak_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>

#include "common/numbers.h"

namespace kestrel::soak {
namespace {

const cv::Scalar kPaper(255, 255, 255);
const cv::Scalar kText(30, 30, 30);
const cv::Scalar kRule(225, 225, 225);
const cv::Scalar kMark(150, 150, 150);
// One colour per process (BGR), in the order they were first sampled.
const std::vector<cv::Scalar> kPalette = {{180, 119, 31}, {14, 127, 255}, {44, 160, 44},
                                          {40, 39, 214},  {189, 103, 148}, {75, 86, 140},
                                          {194, 119, 227}, {127, 127, 127}};
constexpr int kFace = cv::FONT_HERSHEY_SIMPLEX;
constexpr int kSub = 3;  // sub-pixel bits for lines
constexpr int kWidthPx = 1200;

void label(cv::Mat& img, const std::string& s, cv::Point at, double scale = 0.45, const cv::Scalar& c = kText) {
  cv::putText(img, s, at, kFace, scale, c, 1, cv::LINE_AA);
}
int label_width(const std::string& s, double scale = 0.45) {
  int base = 0;
  return cv::getTextSize(s, kFace, scale, 1, &base).width;
}

std::string tick_text(double v, double step) {
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  return fmt::format("{:.{}f}", std::abs(v) < 0.5 * step ? 0.0 : v, decimals);
}

// A panel: data [x0, x1] x [y0, y1] in the pixel rectangle `box`.
struct Panel {
  cv::Rect box;
  double x0, x1, y0, y1;

  cv::Point at(double x, double y) const {
    const double px = box.x + (x - x0) / (x1 - x0) * box.width;
    const double py = box.y + box.height - (y - y0) / (y1 - y0) * box.height;
    return {static_cast<int>(std::lround(px * (1 << kSub))), static_cast<int>(std::lround(py * (1 << kSub)))};
  }
  void segment(cv::Mat& img, double xa, double ya, double xb, double yb, const cv::Scalar& c, int width) const {
    cv::line(img, at(xa, ya), at(xb, yb), c, width, cv::LINE_AA, kSub);
  }
  void frame(cv::Mat& img, const std::string& x_title, const std::string& y_title) const {
    const double xs = nice_step(x1 - x0, 10), ys = nice_step(y1 - y0, 5);
    for (double x = std::ceil(x0 / xs) * xs; x <= x1 + 1e-9 * xs; x += xs) {
      segment(img, x, y0, x, y1, kRule, 1);
      const std::string s = tick_text(x, xs);
      label(img, s, {(at(x, y0).x >> kSub) - label_width(s) / 2, box.br().y + 18});
    }
    for (double y = std::ceil(y0 / ys) * ys; y <= y1 + 1e-9 * ys; y += ys) {
      segment(img, x0, y, x1, y, kRule, 1);
      const std::string s = tick_text(y, ys);
      label(img, s, {box.x - 8 - label_width(s), (at(x0, y).y >> kSub) + 5});
    }
    cv::rectangle(img, box, kText, 1);
    label(img, x_title, {box.br().x - label_width(x_title), box.br().y + 38});
    label(img, y_title, {box.x, box.y - 10}, 0.5);
  }
  // A dashed vertical line at x, named.
  void mark(cv::Mat& img, double x, const std::string& name, int row = 0) const {
    if (!(x > x0 && x < x1)) return;
    const double dash = (y1 - y0) / 40.0;
    for (double y = y0; y < y1; y += 2 * dash) segment(img, x, y, x, std::min(y + dash, y1), kMark, 1);
    label(img, name, {(at(x, y1).x >> kSub) + 4, box.y + 14 + row * 16}, 0.4, kMark);
  }
  // A line through the points with finite y.
  void series(cv::Mat& img, const std::vector<double>& x, const std::vector<double>& y, const cv::Scalar& c,
              int width) const {
    for (size_t i = 1; i < x.size(); ++i)
      if (std::isfinite(y[i - 1]) && std::isfinite(y[i])) segment(img, x[i - 1], y[i - 1], x[i], y[i], c, width);
  }
};

double top_of(const std::vector<std::vector<double>>& ys) {
  double top = 0.0;
  for (const auto& y : ys)
    for (double v : y)
      if (std::isfinite(v)) top = std::max(top, v);
  return top > 0.0 ? 1.1 * top : 1.0;
}

void legend(cv::Mat& img, const std::vector<std::pair<std::string, cv::Scalar>>& entries, cv::Point corner) {
  int x = corner.x;
  for (const auto& [name, colour] : entries) {
    cv::line(img, {x, corner.y - 4}, {x + 28, corner.y - 4}, colour, 3, cv::LINE_AA);
    label(img, name, {x + 34, corner.y});
    x += 34 + label_width(name) + 24;
  }
}

}  // namespace

cv::Mat render_plot(const std::vector<ProcessSample>& samples, const std::vector<ProgressSample>& progress,
                    const Summary& summary, const std::string& title) {
  cv::Mat img(1180, kWidthPx, CV_8UC3, kPaper);
  label(img, title, {20, 30}, 0.6);
  // Each process's growth and verdict, on as many lines as they take.
  std::string line;
  int y = 56;
  for (const ProcessSummary& p : summary.processes) {
    const std::string item = fmt::format(
        "{} {}", p.process,
        std::isfinite(p.growth_mb_per_10min) ? fmt::format("{:+.2f} MB/10 min ({})", p.growth_mb_per_10min, p.verdict)
                                             : p.verdict);
    if (!line.empty() && label_width(line + ",  " + item, 0.42) > kWidthPx - 40) {
      label(img, line, {20, y}, 0.42);
      y += 20;
      line.clear();
    }
    line += (line.empty() ? "" : ",  ") + item;
  }
  label(img, line, {20, y}, 0.42);

  // Each process's series over simulated minutes.
  std::vector<std::string> names;
  std::map<std::string, std::vector<double>> t, rss, cpu;
  std::map<std::string, const ProcessSample*> previous;
  for (const ProcessSample& s : samples) {
    if (!t.count(s.process)) names.push_back(s.process);
    t[s.process].push_back(s.sim_s / 60.0);
    rss[s.process].push_back(s.rss_mb);
    const ProcessSample*& before = previous[s.process];
    cpu[s.process].push_back(before ? cpu_ms_per_frame(*before, s) : kNaN);
    before = &s;
  }
  std::vector<std::pair<std::string, cv::Scalar>> entries;
  for (size_t i = 0; i < names.size(); ++i) entries.push_back({names[i], kPalette[i % kPalette.size()]});
  const double x1 = std::max({summary.sim_s, summary.criteria.run_s, 1.0}) / 60.0;
  const double warm = summary.criteria.warmup_s / 60.0;
  const double fit = summary.processes.empty() ? kNaN : summary.processes.front().fit_from_s / 60.0;

  std::vector<std::vector<double>> all_rss, all_cpu;
  for (const auto& n : names) all_rss.push_back(rss[n]), all_cpu.push_back(cpu[n]);
  const int left = 90, width = kWidthPx - left - 40;
  const Panel memory{cv::Rect(left, 110, width, 440), 0.0, x1, 0.0, top_of(all_rss)};
  memory.frame(img, "simulated minutes", "resident memory (VmRSS), MB");
  memory.mark(img, warm, "warm-up");
  memory.mark(img, fit, "fit from", 1);
  for (size_t i = 0; i < names.size(); ++i) memory.series(img, t[names[i]], rss[names[i]], entries[i].second, 2);
  legend(img, entries, {left + 10, 100 + 440 + 60});

  const Panel per_frame{cv::Rect(left, 650, width, 250), 0.0, x1, 0.0, top_of(all_cpu)};
  per_frame.frame(img, "simulated minutes", "CPU time per camera frame, ms (each process)");
  per_frame.mark(img, warm, "warm-up");
  for (size_t i = 0; i < names.size(); ++i) per_frame.series(img, t[names[i]], cpu[names[i]], entries[i].second, 2);

  std::vector<double> pt, wall, vo;
  for (size_t i = 0; i < progress.size(); ++i) {
    pt.push_back(progress[i].sim_s / 60.0);
    vo.push_back(progress[i].vo_elapsed_ms);
    const int64_t frames = i > 0 ? progress[i].frames - progress[i - 1].frames : 0;
    wall.push_back(frames > 0 ? 1e3 * (progress[i].wall_s - progress[i - 1].wall_s) / static_cast<double>(frames) : kNaN);
  }
  const cv::Scalar kWall(60, 60, 60), kVo = kPalette[1 % kPalette.size()];
  const Panel pace{cv::Rect(left, 960, width, 150), 0.0, x1, 0.0, top_of({wall, vo})};
  pace.frame(img, "simulated minutes", "wall time per frame, the whole system in lock-step; the VO's own time per frame, ms");
  pace.series(img, pt, wall, kWall, 2);
  pace.series(img, pt, vo, kVo, 1);
  legend(img, {{"wall per frame", kWall}, {"VO elapsed_ms", kVo}}, {left + 10, 960 + 150 + 60});
  return img;
}

}  // namespace kestrel::soak
