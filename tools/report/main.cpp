// kestrel-report: a Markdown report (the demo's, fly-plans', any) as one self-contained HTML
// page, its images embedded (html_page.h). tools/report/README.md.

#include <spdlog/spdlog.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/error.h"
#include "tools/report/html_page.h"

namespace {

using namespace kestrel;
namespace fs = std::filesystem;

std::optional<std::string> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream all;
  all << in.rdbuf();
  if (in.bad()) return std::nullopt;
  return all.str();
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("report",
               "Renders a Markdown report as one HTML page that needs no other file: every image it "
               "names by a relative path is embedded. Exit: 0 written; 1 an image it names is missing "
               "(the page is written, with the link); 2 --out is the report itself; 3 the report cannot be read "
               "or the page written.");
  std::string input, output, title;
  app.add_option("report", input, "The Markdown report")->required();
  app.add_option("--out", output, "The HTML page (default: the report's name with .html)");
  app.add_option("--title", title, "The page's title (default: the report's first heading)");

  return app.run(argc, argv, [&]() -> int {
    const fs::path in(input);
    const auto markdown = read_bytes(in);
    if (!markdown) throw InputError(input + ": cannot be read");
    if (title.empty()) {  // the first level-1 heading, outside fenced code
      std::istringstream lines(*markdown);
      bool fenced = false;
      for (std::string line; std::getline(lines, line);) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.rfind("```", 0) == 0) fenced = !fenced;
        if (!fenced && line.rfind("# ", 0) == 0) {
          title = line.substr(2);
          break;
        }
      }
      if (title.empty()) title = in.stem().string();
    }
    const fs::path folder = in.has_parent_path() ? in.parent_path() : fs::path(".");
    const report::HtmlPage page = report::render_page(
        *markdown, title, [&folder](const std::string& relative) { return read_bytes(folder / relative); });
    const fs::path out = output.empty() ? fs::path(in).replace_extension(".html") : fs::path(output);
    std::error_code same_error;
    if (out == in || fs::equivalent(out, in, same_error))
      throw CLI::ValidationError("--out", "is the report itself: it would be overwritten");
    AtomicFile file(out.string());
    file.stream() << page.html;
    file.commit();
    for (const auto& m : page.missing) spdlog::error("{}: the image '{}' it names is not there: linked, not embedded", input, m);
    spdlog::info("wrote {} ({} images embedded, {} KiB)", out.string(), page.embedded.size(), page.html.size() / 1024);
    return page.missing.empty() ? kExitOk : kExitFailure;
  });
}
