// `kestrel plan` and `kestrel plan-experiments` as a user runs them: a plan in the shipped
// floor world (a roadmap that grows until it connects; both BRM label rules), bad world
// and map files named in the error, and the experiments' tables and plot from one command.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "common/image/image_io.h"
#include "test/support/test_support.h"

namespace kestrel::planner {
namespace {

std::vector<std::vector<double>> waypoints(const std::string& out) {
  std::vector<std::vector<double>> rows;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::vector<double> row;
    for (double v; fields >> v;) row.push_back(v);
    rows.push_back(row);
  }
  return rows;
}

const std::vector<std::string> kPrmSeed5 = {"--map",     "floor", "--start",   "2.5",     "2.5",    "1",
                                            "0",         "--goal", "10.5",     "17.5",    "1",      "0",
                                            "--planner", "prm",    "--sampler", "uniform", "--seed", "5"};

TEST(PlanTool, ARoadmapThatDoesNotConnectGrowsUntilItDoes) {
  // Seed 5's 300 samples leave the two rooms unconnected (exit 1); drawn again, they connect.
  std::vector<std::string> fixed{test::tool("plan").string()};
  fixed.insert(fixed.end(), kPrmSeed5.begin(), kPrmSeed5.end());
  fixed.insert(fixed.end(), {"--max-samples", "0"});
  const test::RunResult no = test::run(fixed);
  EXPECT_EQ(no.exit_code, 1) << no.err;
  EXPECT_NE(no.err.find("no path found with 300 samples"), std::string::npos) << no.err;

  std::vector<std::string> grown{test::tool("plan").string()};
  grown.insert(grown.end(), kPrmSeed5.begin(), kPrmSeed5.end());
  const test::RunResult yes = test::run(grown);
  ASSERT_EQ(yes.exit_code, 0) << yes.err;
  const auto path = waypoints(yes.out);
  ASSERT_GE(path.size(), 3u) << yes.out;
  for (const auto& w : path) ASSERT_EQ(w.size(), 5u) << yes.out;  // x y z yaw tr(Sigma)
  EXPECT_EQ(path.front(), (std::vector<double>{2.5, 2.5, 1, 0, 0.4}));
  EXPECT_EQ(std::vector<double>(path.back().begin(), path.back().begin() + 4), (std::vector<double>{10.5, 17.5, 1, 0}));
  double length = 0.0;
  for (size_t i = 1; i < path.size(); ++i)
    length += std::hypot(path[i][0] - path[i - 1][0], path[i][1] - path[i - 1][1]);
  EXPECT_GT(length, std::hypot(8.0, 15.0));  // at least the straight line
  EXPECT_NE(yes.out.find("length"), std::string::npos);
}

double goal_trace(const std::string& out) {
  const std::string key = "goal tr(Sigma) ";
  const size_t at = out.find(key);
  return at == std::string::npos ? -1.0 : std::stod(out.substr(at + key.size()));
}

TEST(PlanTool, CovarianceDominanceEndsBetterLocalisedThanAlgorithm1OnTheDefaultQuery) {
  // The default query (the floor's two far rooms, grown roadmap): the same roadmap searched
  // with both label rules. At the tools' 1 % slack dominance is not always below the trace
  // rule; here it is (0.9307 against 0.9318 when written).
  std::vector<double> trace;
  for (const char* planner : {"brm", "brm-dominance"}) {
    const test::RunResult r = test::run({test::tool("plan").string(), "--planner", planner, "--seed", "1"});
    ASSERT_EQ(r.exit_code, 0) << planner << ": " << r.err;
    const auto path = waypoints(r.out);
    ASSERT_GE(path.size(), 2u) << r.out;
    EXPECT_EQ(path.front(), (std::vector<double>{2.5, 2.5, 1, 0, 0.4}));
    trace.push_back(goal_trace(r.out));
    ASSERT_GT(trace.back(), 0.0) << r.out;
    EXPECT_NEAR(path.back()[4], trace.back(), 1e-6 * trace.back()) << "the header's tr(Sigma) is the goal's";
  }
  EXPECT_LE(trace[1], trace[0]);
}

TEST(PlanTool, BadWorldAndMapFilesAreNamedWithExitCode3) {
  test::TempDir dir;
  std::ofstream(dir / "bad.world") << "wall nonsense\n";
  std::ofstream(dir / "bad.yaml") << "image: nothere.pgm\nresolution: 0.05\n";
  for (const char* name : {"bad.world", "bad.yaml"}) {
    const std::string file = (dir / name).string();
    const test::RunResult r = test::run({test::tool("plan").string(), "--map", file});
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
  }
}

// Naming a map there is not is a usage error (exit 2) that says which there are, before any
// planning; a map file named but absent is input that is not there (exit 3), as a bad one is.
TEST(PlanTool, AnUnknownMapIsExitCode2NamingItAndTheMapsThereAre) {
  const test::RunResult unknown = test::run({test::tool("plan").string(), "--map", "atlantis"}, 20.0);
  EXPECT_EQ(unknown.exit_code, 2) << unknown.err;
  EXPECT_EQ(unknown.err.rfind("kestrel-plan: error: --map: unknown world 'atlantis' (built in: ", 0), 0u)
      << unknown.err;
  for (const char* world : {"room", "floor", "office", "atrium"})
    EXPECT_NE(unknown.err.find(world), std::string::npos) << world << ": " << unknown.err;
  EXPECT_NE(unknown.err.find("or a .world file or an occupancy map .yaml)"), std::string::npos) << unknown.err;
  EXPECT_EQ(unknown.err.find("stata"), std::string::npos) << "kestrel-plan takes the stata map's .yaml itself: "
                                                          << unknown.err;
  EXPECT_TRUE(unknown.out.empty()) << unknown.out;

  const test::RunResult stata = test::run({test::tool("plan").string(), "--map", "stata"}, 20.0);
  EXPECT_EQ(stata.exit_code, 2) << stata.err;
  EXPECT_NE(stata.err.find("kestrel-plan: error: --map: the stata world is a ROS map: give its .yaml as --map"),
            std::string::npos)
      << stata.err;

  test::TempDir dir;
  for (const char* name : {"absent.world", "absent.yaml"}) {
    const std::string file = (dir / name).string();
    const test::RunResult absent = test::run({test::tool("plan").string(), "--map", file}, 20.0);
    EXPECT_EQ(absent.exit_code, 3) << absent.err;
    EXPECT_NE(absent.err.find(file), std::string::npos) << absent.err;
  }
}

TEST(PlanTool, AMapOfAbsurdSizeIsExit3NamingTheFieldNotAGrowingPlan) {
  // resolution: 1000 once made the planner grow to gigabytes; every size is now bounded first.
  test::TempDir dir;
  cv::Mat img(40, 200, CV_8UC1, cv::Scalar(254));
  for (cv::Mat wall : {img.row(0), img.row(39), img.col(0), img.col(199)}) wall.setTo(0);
  image::write_png((dir / "m.png").string(), img);
  const std::pair<std::string, std::string> cases[] = {
      {"resolution: 1000\norigin: [0, 0, 0]\n", ":2: 'resolution' must be in [0.001, 10] m per pixel, got 1000"},
      {"resolution: 0\norigin: [0, 0, 0]\n", ":2: 'resolution' must be in"},
      {"resolution: .nan\norigin: [0, 0, 0]\n", ":2: 'resolution' must be a number"},
      {"resolution: 0.05\norigin: [1e300, 0, 0]\n", ":3: 'origin' x and y must be within"},
      {"resolution: 9\norigin: [0, 0, 0]\n", ":2: 'resolution' 9 m per pixel makes the 200 x 40 pixels"},
  };
  int i = 0;
  for (const auto& [body, expected] : cases) {
    const std::string file = (dir / ("m" + std::to_string(i++) + ".yaml")).string();
    std::ofstream(file) << "image: m.png\n" << body;
    const test::RunResult r = test::run({test::tool("plan").string(), "--map", file}, 60.0);
    EXPECT_EQ(r.exit_code, 3) << body << r.err;
    EXPECT_NE(r.err.find(file + expected), std::string::npos) << r.err;
  }
}

TEST(PlanExperimentsTool, OneCommandWritesTheTableAndThePlot) {
  test::TempDir dir;
  const test::RunResult r =
      test::run({test::tool("plan-experiments").string(), "--world", "floor", "--only", "table5", "--trials", "1",
                 "--out", (dir / "tables.md").string(), "--png-dir", (dir / "figures").string(), "-q"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string md = test::read_file(dir / "tables.md");
  EXPECT_EQ(md, r.out);  // --out holds what was printed
  EXPECT_NE(md.find("### Table 5"), std::string::npos) << md;
  for (const char* row : {"| prm | uniform |", "| brm | su |", "| brm | su-ukf |", "| brm | gaussian |", "| brm | bridge |",
                          "| brm-dominance | su |"})
    EXPECT_NE(md.find(row), std::string::npos) << row << "\n" << md;
  const cv::Mat png = image::read_image((dir / "figures" / "floor_paths.png").string());  // the folder was made
  ASSERT_FALSE(png.empty());
  EXPECT_GT(png.rows, 200);
}

// Outputs that cannot be written are refused before any experiment runs (a whole run takes
// tens of minutes), naming the path: exit 3 at once, nothing printed.
TEST(PlanExperimentsTool, UnwritableOutputsAreRefusedBeforeTheExperimentsRun) {
  test::TempDir dir;
  { std::ofstream(dir / "a-file") << "x"; }
  const std::string png_under_file = (dir / "a-file" / "figures").string();
  const std::string out_in_missing = (dir / "missing" / "tables.md").string();
  for (const std::vector<std::string>& extra : {std::vector<std::string>{"--png-dir", png_under_file},
                                                std::vector<std::string>{"--out", out_in_missing}}) {
    std::vector<std::string> argv = {test::tool("plan-experiments").string(), "--trials", "30", "-q"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    const test::RunResult r = test::run(argv, 20.0);
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_NE(r.err.find(extra[1]), std::string::npos) << r.err;
    EXPECT_EQ(r.out.find("### Table"), std::string::npos) << r.out;
  }
}

TEST(PlanExperimentsTool, WithoutTheStataMapItSaysSoAndGoesOn) {
  const test::RunResult r = test::run({test::tool("plan-experiments").string(), "--world", "stata", "--map",
                                       "/nonexistent/stata.yaml", "--only", "table5", "--trials", "1", "-q"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("Skipped: the map /nonexistent/stata.yaml is absent"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace kestrel::planner
