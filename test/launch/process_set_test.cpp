// Process-set files: what a good file selects, and a one-line error naming the file and line
// for each way a file can be wrong.

#include "tools/launch/process_set.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "common/error.h"
#include "test/support/test_support.h"

namespace kestrel::launch {
namespace {

using test::TempDir;

std::filesystem::path write(const TempDir& dir, const std::string& text) {
  const auto path = dir / "sets.yaml";
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const std::filesystem::path& file) {
  try {
    read_process_sets(file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const char* kGood = R"(# comment
processes:
  - {name: vo, command: vo --fast, side: onboard}
  - name: estimator
    command: estimator
    side: onboard
  - {name: slam, command: /bin/true, side: offboard}
)";

TEST(ProcessSets, ReadsEveryProcessInFileOrder) {
  TempDir dir;
  const ProcessSet all = read_process_sets(write(dir, kGood));
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].name, "vo");
  EXPECT_EQ(all[0].argv, (std::vector<std::string>{"vo", "--fast"}));
  EXPECT_EQ(all[1].side, "onboard");
  EXPECT_EQ(all[2].argv, (std::vector<std::string>{"/bin/true"}));
}

TEST(ProcessSets, SelectsBySideOnlyAndWithout) {
  TempDir dir;
  const ProcessSet all = read_process_sets(write(dir, kGood));
  auto names = [](const ProcessSet& s) {
    std::vector<std::string> n;
    for (const auto& p : s) n.push_back(p.name);
    return n;
  };
  using V = std::vector<std::string>;
  EXPECT_EQ(names(select(all, "onboard", {}, {})), (V{"vo", "estimator"}));
  EXPECT_EQ(names(select(all, "offboard", {}, {})), (V{"slam"}));
  EXPECT_EQ(names(select(all, "all", {}, {"estimator"})), (V{"vo", "slam"}));
  EXPECT_EQ(names(select(all, "all", {"slam", "vo"}, {})), (V{"vo", "slam"}));
  EXPECT_TRUE(select(all, "offboard", {"vo"}, {}).empty());
  EXPECT_THROW(select(all, "ground", {}, {}), InputError);
  EXPECT_THROW(select(all, "all", {"mapper"}, {}), InputError);
  EXPECT_THROW(select(all, "all", {}, {"mapper"}), InputError);
}

TEST(ProcessSets, MalformedFilesNameTheFileAndLine) {
  TempDir dir;
  const auto missing = dir / "absent.yaml";
  EXPECT_NE(error_of(missing).find("absent.yaml: no such file"), std::string::npos);

  struct Case {
    const char* text;
    const char* expected;  // after "sets.yaml"
  };
  const Case cases[] = {
      {"processes: [", "sets.yaml:"},                                           // YAML syntax
      {"procs: []\n", "sets.yaml: expected a top-level 'processes:' list"},
      {"processes:\n  - {name: vo, side: onboard}\n", "sets.yaml:2: a process needs name, command and side"},
      {"processes:\n  - {name: vo, command: vo, side: moon}\n", "sets.yaml:2: side is onboard or offboard"},
      {"processes:\n  - {name: vo, command: '  ', side: onboard}\n", "sets.yaml:2: empty command"},
      {"processes:\n  - {name: vo, command: vo, side: onboard, nice: 5}\n", "sets.yaml:2: unknown key 'nice'"},
      {"processes:\n  - {name: a, command: x, side: onboard}\n  - {name: a, command: y, side: onboard}\n",
       "sets.yaml:3: process 'a' declared twice"},
      {"processes:\n  - {name: a/b, command: x, side: onboard}\n", "sets.yaml:2: a name is one word"},
      {"processes:\n  - {name: a, command: [x, y], side: onboard}\n", "sets.yaml:2"},
  };
  for (const auto& c : cases) {
    const std::string e = error_of(write(dir, c.text));
    EXPECT_NE(e.find(c.expected), std::string::npos) << "for:\n" << c.text << "got: '" << e << "'";
    EXPECT_EQ(e.find('\n'), std::string::npos) << "one line: " << e;
  }
}

TEST(ProcessSets, TheShippedFileIsValidAndHasBothSides) {
  const ProcessSet all = read_process_sets(KESTREL_DEFAULT_PROCESS_SETS);
  EXPECT_FALSE(select(all, "onboard", {}, {}).empty());
  EXPECT_FALSE(select(all, "offboard", {}, {}).empty());
}

TEST(ProcessSets, RunDirIsPutIntoTheArgumentsThatNameIt) {
  ProcessSet set = {{"mapper", {"mapper", "--journal", "{run_dir}/m.journal", "--x={run_dir}:{run_dir}"}, "offboard"},
                    {"vo", {"vo", "--name", "run_dir"}, "onboard"}};
  EXPECT_TRUE(names_run_dir(set));
  EXPECT_FALSE(names_run_dir({set[1]}));  // no folder made for a set that never names it
  set = with_run_dir(set, "/tmp/r");
  EXPECT_FALSE(names_run_dir(set));
  EXPECT_EQ(set[0].argv, (std::vector<std::string>{"mapper", "--journal", "/tmp/r/m.journal", "--x=/tmp/r:/tmp/r"}));
  EXPECT_EQ(set[1].argv, (std::vector<std::string>{"vo", "--name", "run_dir"}));
  // The shipped set journals the mapper's keyframes in the launch's own folder.
  const ProcessSet shipped = with_run_dir(read_process_sets(KESTREL_DEFAULT_PROCESS_SETS), "/R");
  const auto mapper = std::find_if(shipped.begin(), shipped.end(), [](const ProcessSpec& p) { return p.name == "mapper"; });
  ASSERT_NE(mapper, shipped.end());
  EXPECT_EQ(mapper->argv, (std::vector<std::string>{"mapper", "--journal", "/R/mapper.journal"}));
}

// restart_args only from the first restart on: the shipped estimator awaits SLAM's world
// only when restarted (the first one of a launch defines it: issue 39, item 3).
TEST(ProcessSets, RestartArgumentsAreAddedOnlyWhenRestarted) {
  TempDir dir;
  const ProcessSet set = read_process_sets(write(dir, R"(processes:
  - {name: estimator, command: estimator -q, restart_args: "--await-world 1 --x={run_dir}", side: onboard}
  - {name: vo, command: vo, side: onboard}
)"));
  ASSERT_EQ(set.size(), 2u);
  EXPECT_EQ(command_of_start(set[0], 0), (std::vector<std::string>{"estimator", "-q"}));
  EXPECT_EQ(command_of_start(set[0], 1), (std::vector<std::string>{"estimator", "-q", "--await-world", "1", "--x={run_dir}"}));
  EXPECT_EQ(command_of_start(set[1], 3), (std::vector<std::string>{"vo"}));
  EXPECT_TRUE(names_run_dir(set));
  EXPECT_EQ(with_run_dir(set, "/R")[0].restart_args, (std::vector<std::string>{"--await-world", "1", "--x=/R"}));

  const ProcessSet shipped = read_process_sets(KESTREL_DEFAULT_PROCESS_SETS);
  const auto estimator = std::find_if(shipped.begin(), shipped.end(), [](const ProcessSpec& p) { return p.name == "estimator"; });
  ASSERT_NE(estimator, shipped.end());
  const auto first = command_of_start(*estimator, 0), again = command_of_start(*estimator, 1);
  EXPECT_EQ(std::find(first.begin(), first.end(), "--await-world"), first.end())
      << "the first estimator defines the world: nothing to await";
  EXPECT_NE(std::find(again.begin(), again.end(), "--await-world"), again.end())
      << "a restarted estimator awaits the map's world";
}

// One side launched alone joins a system that may be running: its first start is a restart's.
TEST(ProcessSets, ASideLaunchedAloneStartsAsARestartDoes) {
  const ProcessSet set = joining_a_running_system(
      {{"estimator", {"estimator", "-q"}, "onboard", {"--await-world", "1"}}, {"vo", {"vo"}, "onboard"}});
  EXPECT_EQ(command_of_start(set[0], 0), (std::vector<std::string>{"estimator", "-q", "--await-world", "1"}));
  EXPECT_EQ(command_of_start(set[0], 2), (std::vector<std::string>{"estimator", "-q", "--await-world", "1"}))
      << "given once, not again at a restart";
  EXPECT_EQ(command_of_start(set[1], 0), (std::vector<std::string>{"vo"}));
}

// kestrel launch --map DIR: SLAM saves (and, with a map there, loads) it, the mapper journals in
// it, and on an existing map every estimator awaits the map's world, its first start too.
TEST(ProcessSets, ASavedMapIsWiredIntoSlamTheMapperAndTheEstimator) {
  const ProcessSet shipped = read_process_sets(KESTREL_DEFAULT_PROCESS_SETS);
  auto args_of = [](const ProcessSet& set, const std::string& name) {
    for (const auto& p : set)
      if (p.name == name) return p;
    ADD_FAILURE() << name;
    return ProcessSpec{};
  };
  const ProcessSet first = with_saved_map(shipped, "/maps/b1", false);
  EXPECT_EQ(args_of(first, "slam").argv, (std::vector<std::string>{"slam", "--save-map", "/maps/b1"}));
  EXPECT_EQ(args_of(first, "mapper").argv,
            (std::vector<std::string>{"mapper", "--journal", "/maps/b1/mapper.journal", "--journal-is-map"}));
  EXPECT_EQ(args_of(first, "estimator").argv, args_of(shipped, "estimator").argv) << "the first flight defines the world";
  const ProcessSet again = with_saved_map(shipped, "/maps/b1", true);
  EXPECT_EQ(args_of(again, "slam").argv,
            (std::vector<std::string>{"slam", "--map", "/maps/b1", "--save-map", "/maps/b1"}));
  const ProcessSpec estimator = args_of(again, "estimator");
  EXPECT_EQ(estimator.argv, (std::vector<std::string>{"estimator", "--await-world", "30"}));
  EXPECT_TRUE(estimator.restart_args.empty()) << "a restart awaits the map's world as long, once";
  EXPECT_EQ(command_of_start(estimator, 2), estimator.argv);
  EXPECT_EQ(args_of(again, "vo").argv, args_of(shipped, "vo").argv);
  // A set whose slam already names a map gets the launch's, once (a repeated option is exit 2).
  ProcessSet named = shipped;
  for (auto& p : named)
    if (p.name == "slam") p.argv.insert(p.argv.end(), {"--map", "/old", "--save-map", "/old"});
  EXPECT_EQ(args_of(with_saved_map(named, "/maps/b1", true), "slam").argv,
            (std::vector<std::string>{"slam", "--map", "/maps/b1", "--save-map", "/maps/b1"}));
  // Localising only: SLAM adds no keyframes over the map, the mapper updates it from the frames
  // SLAM locates (or keeps it as it is); on a first flight there is nothing to localise in.
  const ProcessSet localising = with_saved_map(shipped, "/maps/b1", true, {30.0, true, true});
  EXPECT_EQ(args_of(localising, "slam").argv,
            (std::vector<std::string>{"slam", "--map", "/maps/b1", "--save-map", "/maps/b1", "--localize-only"}));
  EXPECT_EQ(args_of(localising, "mapper").argv,
            (std::vector<std::string>{"mapper", "--journal", "/maps/b1/mapper.journal", "--journal-is-map",
                                      "--insert-located"}));
  EXPECT_EQ(args_of(with_saved_map(shipped, "/maps/b1", true, {30.0, true, false}), "mapper").argv,
            args_of(again, "mapper").argv);
  EXPECT_EQ(args_of(with_saved_map(shipped, "/maps/b1", false, {30.0, true, true}), "slam").argv,
            args_of(first, "slam").argv);
}

TEST(ResolveExecutable, PrefersKestrelToolsThenPath) {
  TempDir dir;
  const auto tool = dir / "kestrel-thing";
  std::ofstream(tool) << "#!/bin/sh\n";
  std::filesystem::permissions(tool, std::filesystem::perms::owner_all);
  EXPECT_EQ(resolve_executable("thing", dir.path()), tool);
  EXPECT_EQ(resolve_executable("sh", dir.path()).filename(), "sh");  // from PATH
  EXPECT_EQ(resolve_executable(tool.string(), "/nonexistent"), tool);
  try {
    resolve_executable("nothing-like-this", dir.path());
    FAIL() << "resolved a tool that does not exist";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no kestrel-nothing-like-this"), std::string::npos) << e.what();
  }
  EXPECT_THROW(resolve_executable((dir / "missing").string(), dir.path()), InputError);
}

}  // namespace
}  // namespace kestrel::launch
