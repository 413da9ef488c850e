#include "test/support/figures.h"

#include <map>
#include <stdexcept>

#include "tools/figures/figures.h"
#include "tools/figures/render.h"

namespace kestrel::test {
namespace {

std::string figures_path() { return std::string(KESTREL_SOURCE_DIR) + "/results/figures.json"; }

// Loaded once; a file that does not validate is remembered as its message, so every test that
// asks reports the same error rather than a crash.
struct Loaded {
  std::map<std::string, Figure> figures;
  std::map<std::string, std::string> texts;  // id -> why it is not a number
  std::string error;
};

const Loaded& loaded() {
  static const Loaded all = [] {
    Loaded l;
    try {
      const figures::FigureFile file = figures::load(figures_path());
      for (const figures::Figure& f : file.figures) {
        if (!f.is_number()) {
          l.texts[f.id] = "is a text (\"" + f.text + "\"), not a number";
          continue;
        }
        Figure si;
        si.id = f.id;
        si.value = f.value_in_si();
        if (const auto limit = f.limit_in_si()) {
          si.has_limit = true;
          if (limit->min) si.min = *limit->min;
          if (limit->max) si.max = *limit->max;
        }
        si.shown = figures::value_text(file, f);
        l.figures.emplace(f.id, si);
      }
    } catch (const std::exception& e) {
      l.error = e.what();
    }
    return l;
  }();
  return all;
}

}  // namespace

const Figure& figure(const std::string& id) {
  const Loaded& l = loaded();
  if (!l.error.empty()) throw std::runtime_error(l.error);
  if (const auto it = l.figures.find(id); it != l.figures.end()) return it->second;
  if (const auto it = l.texts.find(id); it != l.texts.end())
    throw std::runtime_error("figure " + id + " of " + figures_path() + " " + it->second);
  throw std::runtime_error("no figure " + id + " in " + figures_path());
}

::testing::AssertionResult within_limit(double measured_si, const Figure& f) {
  if (!f.has_limit) return ::testing::AssertionFailure() << f.id << " has no limit in results/figures.json";
  if (measured_si >= f.min && measured_si <= f.max) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "measured " << measured_si << " (SI) is outside " << f.id << "'s limit ["
                                       << f.min << ", " << f.max << "] (SI; the figure is " << f.shown << ")";
}

::testing::AssertionResult no_worse_than(double measured_si, const Figure& f, double factor) {
  if (measured_si <= factor * f.value) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "measured " << measured_si << " (SI) is above " << factor << " x " << f.id
                                       << " = " << factor * f.value << " (the figure is " << f.shown << ")";
}

}  // namespace kestrel::test
