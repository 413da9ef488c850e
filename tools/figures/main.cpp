// kestrel-figures: checks (--check) or regenerates (--write) the figures tables of every README
// from results/figures.json, the one file that holds kestrel's headline figures. See
// tools/figures/README.md and CONTRIBUTING.md, "Figures".

#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/error.h"
#include "tools/figures/figures.h"
#include "tools/figures/render.h"

namespace {

using namespace kestrel;
namespace fs = std::filesystem;

// The README's text, or nothing if the file is absent; InputError if it is there but unreadable.
std::optional<std::string> read_readme(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  std::ostringstream all;
  all << in.rdbuf();
  if (!in || in.bad()) throw InputError(path.string() + ": cannot be read");
  return all.str();
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("figures",
               "Checks or regenerates the figures tables of the READMEs (between <!-- figures:begin --> "
               "and <!-- figures:end -->) from results/figures.json.");
  app.option_defaults()->always_capture_default();
  std::string root = ".";
  std::string file = "results/figures.json";
  bool check = false, rewrite = false;
  app.add_option("--root", root, "The repository's root; the READMEs and --file are relative to it");
  app.add_option("--file", file, "The figures file (relative to --root unless absolute)");
  auto* check_flag = app.add_flag("--check", check, "Exit 1 naming each README whose tables differ from the file");
  app.add_flag("--write", rewrite, "Rewrite each README's tables from the file (atomically)")->excludes(check_flag);

  return app.run(argc, argv, [&]() -> int {
    if (!check && !rewrite) throw CLI::RequiredError("--check or --write");
    const fs::path base(root);
    const fs::path figures_path = fs::path(file).is_absolute() ? fs::path(file) : base / file;
    const figures::FigureFile loaded = figures::load(figures_path.string());

    int differ = 0, checked = 0;
    for (const std::string& component : figures::readme_components()) {
      const std::string& name = figures::readme_path(component);
      const auto text = read_readme(base / name);
      bool has_figures = false;
      for (const figures::Figure& f : loaded.figures) has_figures = has_figures || f.component == component;
      if (!text) {
        // A README the file has figures for must be there; one it has none for may be absent.
        if (has_figures) throw InputError((base / name).string() + ": missing (" + loaded.source + " has figures for it)");
        continue;
      }
      if (!has_figures && !figures::has_figures_block(*text)) continue;
      const std::string rendered = figures::render_readme(loaded, component, *text, name);
      ++checked;
      if (rendered == *text) continue;
      if (rewrite) {
        write_file_atomically((base / name).string(), rendered);
        std::cout << "wrote " << name << "\n";
      } else {
        std::cout << name << ": its figures tables differ from " << file << " (./kestrel figures --write)\n";
        ++differ;
      }
    }
    if (check && differ == 0)
      std::cout << checked << " READMEs match " << file << " (" << loaded.figures.size() << " figures)\n";
    return differ == 0 ? kExitOk : kExitFailure;
  });
}
