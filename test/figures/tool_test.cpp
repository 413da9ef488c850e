// The built `kestrel figures` on a small repository of its own: --check exits 1 naming each
// README that differs, --write rewrites it (and only it) so that --check then passes, and a
// bad command line, figures file or README exits with the README's codes (2, 3).

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "test/support/test_support.h"

namespace kestrel::test {
namespace {

namespace fs = std::filesystem;

const char* kFigures = R"({"figures": [
  {"id": "control.l.path", "component": "control", "figure": "L", "data": "sim", "value": 5.4, "unit": "cm",
   "target": "", "command": "`control_vehicle_test`", "build": "Release", "date": "2026-11-27"},
  {"id": "vo.fr1_xyz.ate", "component": "vo", "figure": "ATE", "data": "fr1_xyz", "value": 0.94, "unit": "cm",
   "target": "≤ 1.2 cm", "command": "`kestrel vo`", "build": "Release", "date": "2026-11-27"}
]})";

const char* kControlTable =
    "| figure | data | value | target | command | build | date |\n"
    "|---|---|---|---|---|---|---|\n"
    "| L | sim | 5.4 cm | — | `control_vehicle_test` | Release | 2026-11-27 |\n";
const char* kVoTable =
    "| figure | data | value | target | command | build | date |\n"
    "|---|---|---|---|---|---|---|\n"
    "| ATE | fr1_xyz | 0.94 cm | ≤ 1.2 cm | `kestrel vo` | Release | 2026-11-27 |\n";

void write(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

class FiguresTool : public ::testing::Test {
 protected:
  void SetUp() override {
    write(root_ / "results" / "figures.json", kFigures);
    write(root_ / "control" / "README.md", "# control\n<!-- figures:begin -->\n| stale |\n<!-- figures:end -->\nend\n");
    write(root_ / "vo" / "README.md", std::string("# vo\n<!-- figures:begin -->\n") + kVoTable + "<!-- figures:end -->\n");
  }
  RunResult figures(const std::vector<std::string>& args) {
    std::vector<std::string> argv = {tool("figures").string(), "--root", root_.path().string()};
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv, 60.0);
  }
  TempDir root_;
};

TEST_F(FiguresTool, CheckNamesTheReadmeThatDiffersAndWriteFixesOnlyIt) {
  const fs::path vo_readme = root_ / "vo" / "README.md";
  const auto vo_before = fs::last_write_time(vo_readme);
  const RunResult check = figures({"--check"});
  EXPECT_EQ(check.exit_code, 1) << check.err;
  EXPECT_NE(check.out.find("control/README.md"), std::string::npos) << check.out;
  EXPECT_EQ(check.out.find("vo/README.md"), std::string::npos) << check.out;

  const RunResult written = figures({"--write"});
  EXPECT_EQ(written.exit_code, 0) << written.err;
  EXPECT_EQ(read_file(root_ / "control" / "README.md"),
            std::string("# control\n<!-- figures:begin -->\n") + kControlTable + "<!-- figures:end -->\nend\n");
  EXPECT_EQ(fs::last_write_time(vo_readme), vo_before) << "a README that matched was rewritten";
  for (const auto& entry : fs::directory_iterator(root_ / "control"))
    EXPECT_EQ(entry.path().filename(), "README.md") << "a temporary was left behind";

  const RunResult again = figures({"--check"});
  EXPECT_EQ(again.exit_code, 0) << again.out << again.err;
}

TEST_F(FiguresTool, ABadCommandLineExits2) {
  EXPECT_EQ(figures({}).exit_code, 2) << "neither --check nor --write";
  EXPECT_EQ(figures({"--check", "--write"}).exit_code, 2);
}

TEST_F(FiguresTool, ABadFiguresFileOrReadmeExits3NamingIt) {
  write(root_ / "results" / "figures.json", R"({"figures": [{"id": "vo.a"}]})");
  RunResult r = figures({"--check"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("figures.json: figures[0] ('vo.a')"), std::string::npos) << r.err;

  write(root_ / "results" / "figures.json", kFigures);
  write(root_ / "vo" / "README.md", "# vo, its table gone\n");
  r = figures({"--write"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("vo/README.md: no figures block"), std::string::npos) << r.err;

  fs::remove(root_ / "vo" / "README.md");
  r = figures({"--check"});
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("vo/README.md: missing"), std::string::npos) << r.err;

  EXPECT_EQ(figures({"--check", "--file", "nowhere.json"}).exit_code, 3);
}

}  // namespace
}  // namespace kestrel::test
