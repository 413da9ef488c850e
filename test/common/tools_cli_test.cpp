// Every tool the multi-call executable lists (kestrel-tools --help), and those that are
// executables of their own (bag-import, bag-export, ros-bridge) where built, as a user runs it: its
// --print-config read back with --config prints the same text, also with every default it
// shows uncommented; --print-config, --config and --help are never in that file; a non-finite
// value for any floating-point option and an unknown option are usage errors (exit 2). Each run
// ends in --print-config or a parse error, so no tool ever starts its work (or LCM).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "common/error.h"
#include "test/support/test_support.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;
using test::RunResult;

// What a tool needs before it parses at all (its required options and positionals): {dir}
// is an empty folder, {file} an empty file, {out} a path that does not exist.
const std::map<std::string, std::vector<std::string>>& required_arguments() {
  static const std::map<std::string, std::vector<std::string>> kArgs = {
      {"tum-play", {"{dir}"}},
      {"tum-to-fakenect", {"{dir}", "{out}"}},
      {"sim-realism", {"--tum", "{dir}"}},
      {"vo-ablation", {"--tum", "{dir}"}},
      {"vo-crossval", {"--tum", "{dir}", "--tum", "{dir}"}},
      {"estimate", {"--log", "{file}", "--out", "{out}"}},
      {"fit-vo-noise", {"--log", "{file}"}},
      {"hold", {"--log", "{file}"}},
      {"posegraph", {"{file}"}},
      {"slam-vocabulary", {"--tum", "{dir}", "--out", "{out}"}},
      {"map", {"--out", "{out}"}},
      {"goto", {"--goal", "1", "2", "1.5", "0.25"}},
      {"eval", {"--est", "{file}"}},
      {"replay", {"{file}"}},
      {"report", {"{file}"}},
      {"launch", {"all"}},
      {"bag-import", {"{file}", "--log", "{out}"}},
      {"bag-export", {"{file}", "--bag", "{out}"}},
  };
  return kArgs;
}

class EveryTool : public ::testing::Test {
 protected:
  void SetUp() override {
    const RunResult list = test::run({test::tool("tools").string(), "--help"}, 30.0);
    if (list.exit_code != 0) KESTREL_SKIP_ENVIRONMENT() << "kestrel-tools is not built: " << list.err;
    std::istringstream in(list.out);
    std::string line;
    std::getline(in, line);  // "usage: ..."
    while (std::getline(in, line))
      if (line.rfind("  ", 0) == 0) tools_.push_back(line.substr(2));
    ASSERT_GE(tools_.size(), 20u) << list.out;
    // The tools that are executables of their own (ros/: ROS's libraries), where built.
    for (const char* own : {"bag-import", "bag-export", "ros-bridge"})
      if (fs::exists(test::tool(own))) tools_.push_back(own);
    fs::create_directory(dir_ / "seq");
    std::ofstream(dir_ / "empty.file").flush();
  }

  // The tool's command line: its required arguments, then `args`.
  std::vector<std::string> command(const std::string& tool, const std::vector<std::string>& args) const {
    std::vector<std::string> argv = {test::tool(tool).string()};
    const auto it = required_arguments().find(tool);
    if (it != required_arguments().end())
      for (std::string a : it->second) {
        if (a == "{dir}") a = (dir_ / "seq").string();
        if (a == "{file}") a = (dir_ / "empty.file").string();
        if (a == "{out}") a = (dir_ / "out" / "x").string();
        argv.push_back(a);
      }
    argv.insert(argv.end(), args.begin(), args.end());
    return argv;
  }

  RunResult print_config(const std::string& tool, std::vector<std::string> args) const {
    args.push_back("--print-config");
    return test::run(command(tool, args), 30.0);
  }

  RunResult read_back(const std::string& tool, const std::string& ini, const std::string& name) const {
    const fs::path file = dir_ / (tool + "." + name + ".ini");
    std::ofstream(file) << ini;
    return test::run({test::tool(tool).string(), "--config", file.string(), "--print-config"}, 30.0);
  }

  std::vector<std::string> tools_;
  test::TempDir dir_;
};

// `ini` with every shown default ("# key = value") made a setting.
std::string uncommented(const std::string& ini) {
  static const std::regex kShownDefault(R"(^# [A-Za-z0-9][A-Za-z0-9_-]* = .+$)");
  std::string out;
  std::istringstream in(ini);
  for (std::string line; std::getline(in, line);)
    out += (std::regex_match(line, kShownDefault) ? line.substr(2) : line) + "\n";
  return out;
}

TEST_F(EveryTool, PrintConfigReadBackWithConfigPrintsTheSame) {
  for (const std::string& tool : tools_) {
    SCOPED_TRACE("kestrel-" + tool);
    const RunResult first = print_config(tool, {});
    ASSERT_EQ(first.exit_code, kExitOk) << first.err << "(a new required option? add it to required_arguments())";
    std::istringstream lines(first.out);
    for (std::string line; std::getline(lines, line);)
      for (const std::string key : {"print-config", "config", "help"})
        EXPECT_NE(line.rfind(key + " ", 0), 0u) << line;
    // The required arguments came from the command line; now they come from the file alone.
    const RunResult again = read_back(tool, first.out, "printed");
    EXPECT_EQ(again.exit_code, kExitOk) << again.err << "\n" << first.out;
    EXPECT_EQ(again.out, first.out);
  }
}

TEST_F(EveryTool, EveryDefaultItShowsIsAValueItTakes) {
  for (const std::string& tool : tools_) {
    SCOPED_TRACE("kestrel-" + tool);
    const RunResult first = print_config(tool, {});
    ASSERT_EQ(first.exit_code, kExitOk) << first.err;
    const std::string all_set = uncommented(first.out);
    const RunResult again = read_back(tool, all_set, "defaults");
    EXPECT_EQ(again.exit_code, kExitOk) << again.err << "\n" << all_set;
    EXPECT_EQ(again.out, all_set);
  }
}

TEST_F(EveryTool, ANonFiniteNumberIsAUsageError) {
  static const std::regex kFloatOption(R"(^\s+(?:-[A-Za-z],)?--([A-Za-z0-9][A-Za-z0-9_-]*)\S* FLOAT)");
  static const std::regex kCount(R"(At least (\d+) required)");
  int checked = 0;
  for (const std::string& tool : tools_) {
    SCOPED_TRACE("kestrel-" + tool);
    const RunResult help = test::run({test::tool(tool).string(), "--help"}, 30.0);
    ASSERT_EQ(help.exit_code, kExitOk) << help.err;
    const auto required = required_arguments().find(tool);
    std::istringstream lines(help.out);
    int option_index = 0;
    for (std::string line; std::getline(lines, line);) {
      std::smatch m;
      if (!std::regex_search(line, m, kFloatOption)) continue;
      const std::string key = m[1];
      if (required != required_arguments().end() &&
          std::find(required->second.begin(), required->second.end(), "--" + key) != required->second.end())
        continue;  // given on the command line, which a file does not override
      // One non-finite spelling per option, in turn (a run takes a third of a second). From a
      // file, where "-inf" cannot pass for an option.
      static const char* const kBad[] = {"inf", "nan", "-inf", "1e999"};
      const std::string bad = kBad[option_index++ % 4];
      const fs::path file = dir_ / (tool + ".bad.ini");
      std::ofstream(file) << key << " = " << bad << "\n";
      RunResult r = print_config(tool, {"--config", file.string()});
      std::smatch count;
      if (std::regex_search(r.err, count, kCount)) {  // a vector: as many values as it takes
        std::ofstream list(file);
        list << key << " = [" << bad;
        for (int i = 1; i < std::stoi(count[1]); ++i) list << ", " << bad;
        list << "]\n";
        list.close();
        r = print_config(tool, {"--config", file.string()});
      }
      EXPECT_EQ(r.exit_code, kExitUsage) << key << " = " << bad << ": " << r.err << r.out;
      EXPECT_NE(r.err.find("kestrel-" + tool + ": error: --" + key + ": must be"), std::string::npos)
          << key << " = " << bad << ": " << r.err;
      ++checked;
    }
  }
  EXPECT_GT(checked, 100);  // the tools have dozens of floating-point options
}

TEST_F(EveryTool, AnUnknownOptionIsAUsageError) {
  for (const std::string& tool : tools_) {
    SCOPED_TRACE("kestrel-" + tool);
    const RunResult r = print_config(tool, {"--no-such-option-anywhere"});
    EXPECT_EQ(r.exit_code, kExitUsage) << r.err;
    EXPECT_NE(r.err.find("kestrel-" + tool + ": error: "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--no-such-option-anywhere"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
}

}  // namespace
}  // namespace kestrel
