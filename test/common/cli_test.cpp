// cli::App's configuration files and its usage errors, in process: an app with an option of
// every kind CLI11 offers (strings, numbers, choices, a name->enum transform, fixed-size and
// repeatable vectors, a custom parser, plain, negatable and counting flags, a positional),
// printed with --print-config, read back with --config, printed again; and the errors a user
// meets: non-finite numbers, ranges, bad or unknown lines in a file, bytes that do not print.

#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/error.h"
#include "test/support/test_support.h"

namespace kestrel::cli {
namespace {

enum class Filter { kEkf, kUkf };

struct Settings {
  std::string name = "vo";
  std::string sensor;  // empty: chosen later; a choice, so "" itself is not a valid value
  double rate = 1.0 / 3.0;  // more digits than CLI11's default string keeps
  int seed = 1;
  double gate = 0.0;
  std::vector<double> intrinsics{525, 525, 319.5, 239.5};
  std::vector<std::string> settings;
  Filter filter = Filter::kEkf;
  std::vector<double> sigma{0.005, 0.008};
  bool loop = false;
  bool reset = true;
  std::string folder;
  std::string channels;
  double length = 0.0;  // 0: not set, which --length itself does not take
};

// Declares every kind of option over `s`; `body_ran` tells whether parsing let the body run.
struct TestApp {
  Settings s;
  App app{"test", "An app with one option of each kind"};
  TestApp() {
    app.add_option("folder", s.folder, "A positional");
    app.add_option("--name", s.name, "A string")->capture_default_str();
    app.add_option("--sensor", s.sensor, "A choice without a default")->check(CLI::IsMember({"simulator", "kinect1"}));
    app.add_option("--rate", s.rate, "A double")->check(Positive);
    app.add_option("--seed", s.seed, "An integer")->check(CLI::Range(1, 16));
    app.add_option("--gate", s.gate, "A double without a check");
    app.add_option("--intrinsics", s.intrinsics, "Four doubles")->expected(4)->delimiter(',');
    app.add_option("--set", s.settings, "Repeatable KEY=VALUE");
    static const std::map<std::string, Filter> kFilters{{"ekf", Filter::kEkf}, {"ukf", Filter::kUkf}};
    app.add_option("--filter", s.filter, "A name turned into an enum")
        ->transform(CLI::CheckedTransformer(kFilters, CLI::ignore_case))
        ->default_str("ekf");
    app.add_option_function<std::vector<double>>(
           "--sigma", [this](const std::vector<double>& v) { s.sigma = v; }, "A custom parser")
        ->expected(2)->delimiter(',')->default_str("0.005,0.008");
    app.add_flag("--loop", s.loop, "A flag");
    app.add_flag("--reset,!--no-reset", s.reset, "A flag that is on by default");
    app.add_option("--channels", s.channels, "A regex");
    app.add_option("--gap", s.gate, "Non-negative")->check(CLI::NonNegativeNumber);
    app.add_option("--length", s.length, "Positive, 0 when not set")->check(Positive);
  }
};

struct Outcome {
  int exit_code = -1;
  std::string out, err;
  bool body_ran = false;
};

Outcome run(TestApp& t, std::vector<std::string> args) {
  args.insert(args.begin(), "kestrel-test");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  Outcome o;
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  o.exit_code = t.app.run(static_cast<int>(argv.size()), argv.data(), [&] {
    o.body_ran = true;
    return kExitOk;
  });
  o.out = ::testing::internal::GetCapturedStdout();
  o.err = ::testing::internal::GetCapturedStderr();
  return o;
}

Outcome run(std::vector<std::string> args) {
  TestApp t;
  return run(t, std::move(args));
}

void write(const std::filesystem::path& path, const std::string& text) { std::ofstream(path) << text; }

// The lines of `ini` that set something (not comments, not blank).
std::vector<std::string> settings_of(const std::string& ini) {
  std::vector<std::string> lines;
  std::istringstream in(ini);
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') lines.push_back(line);
  return lines;
}

TEST(CliConfig, EveryKindOfOptionRoundTripsThroughPrintConfig) {
  test::TempDir dir;
  const std::vector<std::string> args = {
      "some folder", "--name", "a \"quoted\", spaced # name\\", "--sensor", "kinect1", "--rate", "0.123456789012",
      "--seed", "7", "--intrinsics", "1.5,2,3,4", "--set", "a=1,2", "--set", "b=\xff\x01", "--filter", "UKF",
      "--sigma", "0.25,0.5", "--loop", "--no-reset", "-v", "-v", "--channels", "CAM.*#x", "--gap", "0"};
  TestApp first;
  std::vector<std::string> printing = args;
  printing.push_back("--print-config");
  const Outcome printed = run(first, printing);
  ASSERT_EQ(printed.exit_code, kExitOk) << printed.err;
  EXPECT_FALSE(printed.body_ran);
  write(dir / "a.ini", printed.out);

  // Read back, the file gives the very values the command line gave.
  TestApp second;
  const Outcome read = run(second, {"--config", (dir / "a.ini").string()});
  ASSERT_EQ(read.exit_code, kExitOk) << read.err << "\n" << printed.out;
  ASSERT_TRUE(read.body_ran);
  const Settings& a = first.s;
  const Settings& b = second.s;
  EXPECT_EQ(b.folder, "some folder");
  EXPECT_EQ(b.name, a.name);
  EXPECT_EQ(b.sensor, "kinect1");
  EXPECT_EQ(b.rate, 0.123456789012);  // exact: written as typed, not at six digits
  EXPECT_EQ(b.seed, 7);
  EXPECT_EQ(b.intrinsics, (std::vector<double>{1.5, 2, 3, 4}));
  EXPECT_EQ(b.settings, (std::vector<std::string>{"a=1,2", "b=\xff\x01"}));
  EXPECT_EQ(b.filter, Filter::kUkf);
  EXPECT_EQ(b.sigma, (std::vector<double>{0.25, 0.5}));
  EXPECT_TRUE(b.loop);
  EXPECT_FALSE(b.reset);
  EXPECT_EQ(b.channels, "CAM.*#x");
  EXPECT_EQ(b.gate, 0.0);

  // The name is written as typed ("UKF"), not as the enum's number CLI11 holds.
  EXPECT_NE(printed.out.find("filter = \"UKF\""), std::string::npos) << printed.out;
  EXPECT_NE(printed.out.find("verbose = 2"), std::string::npos) << printed.out;
  // And it prints the same text again.
  TestApp third;
  const Outcome again = run(third, {"--config", (dir / "a.ini").string(), "--print-config"});
  ASSERT_EQ(again.exit_code, kExitOk) << again.err;
  EXPECT_EQ(again.out, printed.out);
}

TEST(CliConfig, DefaultsAreCommentsThatReadBackWhenUncommented) {
  test::TempDir dir;
  const Outcome printed = run({"--print-config"});
  ASSERT_EQ(printed.exit_code, kExitOk) << printed.err;
  EXPECT_TRUE(settings_of(printed.out).empty()) << printed.out;  // nothing was set
  EXPECT_NE(printed.out.find("# sensor =\n"), std::string::npos) << printed.out;  // no default to show
  EXPECT_NE(printed.out.find("# intrinsics = [525, 525, 319.5, 239.5]"), std::string::npos) << printed.out;
  EXPECT_NE(printed.out.find("# sigma = [0.005, 0.008]"), std::string::npos) << printed.out;
  EXPECT_NE(printed.out.find("# filter = \"ekf\""), std::string::npos) << printed.out;
  EXPECT_NE(printed.out.find("# length =\n"), std::string::npos) << printed.out;  // 0 is not a length

  // Every default shown as "# key = value" is a value the option takes.
  std::string uncommented;
  std::istringstream in(printed.out);
  for (std::string line; std::getline(in, line);) {
    const bool shown_default = line.rfind("# ", 0) == 0 && line.find(" = ") != std::string::npos &&
                               line.find(' ', 2) == line.find(" = ");
    uncommented += (shown_default ? line.substr(2) : line) + "\n";
  }
  write(dir / "defaults.ini", uncommented);
  TestApp t;
  const Outcome read = run(t, {"--config", (dir / "defaults.ini").string(), "--print-config"});
  ASSERT_EQ(read.exit_code, kExitOk) << read.err << "\n" << uncommented;
  EXPECT_EQ(read.out, uncommented);
  EXPECT_EQ(t.s.intrinsics, (std::vector<double>{525, 525, 319.5, 239.5}));
}

TEST(CliConfig, PrintConfigConfigAndHelpAreNeverWritten) {
  test::TempDir dir;
  write(dir / "a.ini", "name = x\n");
  const Outcome printed = run({"--config", (dir / "a.ini").string(), "--print-config"});
  ASSERT_EQ(printed.exit_code, kExitOk) << printed.err;
  EXPECT_EQ(settings_of(printed.out), std::vector<std::string>{"name = \"x\""});
  for (const char* key : {"print-config", "config", "help"})
    for (const std::string& line : settings_of(printed.out)) EXPECT_NE(line.rfind(key, 0), 0u) << line;
  // A file that holds one of them (as CLI11's own --print-config wrote) is refused, naming the line.
  write(dir / "b.ini", "# a file\nname = x\nprint-config=true\n");
  const Outcome refused = run({"--config", (dir / "b.ini").string()});
  EXPECT_EQ(refused.exit_code, kExitUsage);
  EXPECT_NE(refused.err.find((dir / "b.ini").string() + ":3: 'print-config' cannot be set"), std::string::npos)
      << refused.err;
}

TEST(CliConfig, ABadFileIsAUsageErrorNamingTheLine) {
  test::TempDir dir;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"name = x\nbogus = 1\n", ":2: unknown key 'bogus'"},
      {"name = x\nname = y\n", ":2: 'name' is set again (first on line 1)"},
      {"\nname = \"x\n", ":2: a string without its closing quote"},
      {"intrinsics = [1, 2,\n 3, 4\n", ":1: a list without its closing ']'"},
      {"intrinsics = [1, 2, 3, 4] 5\n", ":1: text after the list's ']'"},
      {"[section]\nname = x\n", ":1: '[section]': sections are not used"},
      {"two words\n", ":1: expected KEY = VALUE"},
      {"intrinsics = [1, , 3, 4]\n", ":1: an empty element in a list"},
      {"sigma = 0.1,,0.2\n", ":1: an empty element between two ','"},
      {"name = x\nsigma = 0.1,\n", ":2: nothing after the last ','"},
      {"name = \"x\"y\n", ":1: text right after a closing quote"},
  };
  for (const auto& [text, expected] : cases) {
    write(dir / "bad.ini", text);
    const Outcome r = run({"--config", (dir / "bad.ini").string()});
    EXPECT_EQ(r.exit_code, kExitUsage) << text;
    EXPECT_FALSE(r.body_ran) << text;
    EXPECT_NE(r.err.find("kestrel-test: error: " + (dir / "bad.ini").string() + expected), std::string::npos)
        << text << "\n" << r.err;
  }
}

TEST(CliConfig, ReadsHandWrittenAndCli11StyleValues) {
  test::TempDir dir;
  write(dir / "a.ini",
        "; a comment\n"
        "intrinsics=[1,2,3,4]\n"       // CLI11's and tum-to-fakenect's form
        "sigma = 0.1, 0.2   # why\n"   // a bare list, a trailing comment
        "set = [\"a=1\",\n"            // a list over two lines
        "       'b=\"2\"']\n"
        "name = 'C:\\dir'\n"           // literal
        "channels = \"\\\\d+\\x41\"\n"  // escapes
        "loop\n");                     // a bare flag
  TestApp t;
  const Outcome r = run(t, {"--config", (dir / "a.ini").string()});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_EQ(t.s.intrinsics, (std::vector<double>{1, 2, 3, 4}));
  EXPECT_EQ(t.s.sigma, (std::vector<double>{0.1, 0.2}));
  EXPECT_EQ(t.s.settings, (std::vector<std::string>{"a=1", "b=\"2\""}));
  EXPECT_EQ(t.s.name, "C:\\dir");
  EXPECT_EQ(t.s.channels, "\\d+A");
  EXPECT_TRUE(t.s.loop);
}

TEST(CliErrors, NonFiniteNumbersAreUsageErrors) {
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"--gate", "inf"}, {"--gate", "nan"}, {"--gate=-inf"}, {"--gate", "1e999"}, {"--rate", "inf"},
           {"--intrinsics", "1,2,nan,4"}, {"--sigma", "0.1,inf"}, {"--gap", "nan"}, {"--gate", "INFINITY"}}) {
    const Outcome r = run(args);
    EXPECT_EQ(r.exit_code, kExitUsage) << args[0];
    EXPECT_FALSE(r.body_ran) << args[0];
    EXPECT_EQ(r.err.rfind("kestrel-test: error: --", 0), 0u) << r.err;
  }
  const Outcome r = run({"--gate", "inf"});
  EXPECT_NE(r.err.find("--gate: must be a finite number, got 'inf'"), std::string::npos) << r.err;
  // The same from a configuration file.
  test::TempDir dir;
  write(dir / "a.ini", "gate = nan\n");
  EXPECT_EQ(run({"--config", (dir / "a.ini").string()}).exit_code, kExitUsage);
  EXPECT_EQ(run({"--gate", "1e300"}).exit_code, kExitOk);  // large, but a number
}

TEST(CliErrors, RangesReadAsTheirBounds) {
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--gap", "-1"}, "--gap: must be a number >= 0, got '-1'"},
      {{"--seed", "17"}, "--seed: must be an integer in [1, 16], got '17'"},
      {{"--rate", "-2"}, "--rate: must be a number greater than 0, got '-2'"},
  };
  for (const auto& [args, expected] : cases) {
    const Outcome r = run(args);
    EXPECT_EQ(r.exit_code, kExitUsage);
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
    EXPECT_LT(r.err.size(), 200u) << r.err;  // no 309-digit bound
  }
  TestApp t;
  t.app.add_option("--tilt", t.s.gate, "Degrees")->check(CLI::Range(-90.0, 90.0));
  t.app.add_option("--noise", t.s.gate, "Tiny")->check(CLI::Range(1e-12, 1e9));
  EXPECT_NE(run(t, {"--tilt", "100"}).err.find("--tilt: must be a number in [-90, 90], got '100'"), std::string::npos);
  TestApp u;
  u.app.add_option("--noise", u.s.gate, "Tiny")->check(CLI::Range(1e-12, 1e9));
  EXPECT_NE(run(u, {"--noise", "0"}).err.find("--noise: must be a number in [1e-12, 1e+09], got '0'"),
            std::string::npos);
}

TEST(CliErrors, BytesThatDoNotPrintAreEscaped) {
  const Outcome r = run({"--sensor", "a\x01\xff\x1b[2Jb"});
  EXPECT_EQ(r.exit_code, kExitUsage);
  EXPECT_NE(r.err.find("a\\x01\\xFF\\x1B[2Jb"), std::string::npos) << r.err;
  for (const char c : r.err) {
    const auto byte = static_cast<unsigned char>(c);
    EXPECT_TRUE(c == '\n' || (byte >= 0x20 && byte < 0x7F)) << int(byte);
  }
  // What the body throws is escaped too; valid UTF-8 is kept.
  TestApp t;
  std::vector<std::string> args = {"kestrel-test"};
  std::vector<char*> argv{args[0].data()};
  ::testing::internal::CaptureStderr();
  const int code = t.app.run(1, argv.data(), []() -> int { throw InputError("f.txt:1: got 'x\x7f\n' (m\xc2\xb2)"); });
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(code, kExitBadInput);
  EXPECT_EQ(err, "kestrel-test: error: f.txt:1: got 'x\\x7F\\n' (m\xc2\xb2)\n");
  EXPECT_EQ(printable("ok \xe2\x82\xac \xc0\xaf \xed\xa0\x80"), "ok \xe2\x82\xac \\xC0\\xAF \\xED\\xA0\\x80");
}

TEST(CliErrors, UnknownOptionsAndBadValuesExit2BeforeTheBody) {
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
           {"--bogus"}, {"--seed", "x"}, {"--sensor", ""}, {"--intrinsics", "1,2"}, {"--filter", "kalman"},
           {"--config", "/nonexistent/kestrel.ini"}}) {
    const Outcome r = run(args);
    EXPECT_EQ(r.exit_code, kExitUsage) << args[0];
    EXPECT_FALSE(r.body_ran) << args[0];
    EXPECT_EQ(r.err.rfind("kestrel-test: error: ", 0), 0u) << r.err;
  }
}

TEST(CliErrors, AToolThatRunsACommandTakesNoUnknownOptionForIt) {
  // kestrel-isolated's form: what follows its own options is a command.
  const auto command_of = [](std::vector<std::string> args, std::vector<std::string>* command) {
    App app("prefix", "Runs a command");
    app.prefix_command();
    args.insert(args.begin(), "kestrel-prefix");
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    ::testing::internal::CaptureStderr();
    const int code = app.run(static_cast<int>(argv.size()), argv.data(), [&] {
      *command = app.remaining();
      return kExitOk;
    });
    const std::string err = ::testing::internal::GetCapturedStderr();
    return std::make_pair(code, err);
  };
  std::vector<std::string> command;
  auto [code, err] = command_of({"--bogus", "x"}, &command);
  EXPECT_EQ(code, kExitUsage);
  EXPECT_NE(err.find("kestrel-prefix: error: unknown option '--bogus'"), std::string::npos) << err;
  EXPECT_TRUE(command.empty());
  std::tie(code, err) = command_of({"-q", "ls", "--bogus"}, &command);
  EXPECT_EQ(code, kExitOk) << err;
  EXPECT_EQ(command, (std::vector<std::string>{"ls", "--bogus"}));
  std::tie(code, err) = command_of({"--", "-dash"}, &command);
  EXPECT_EQ(code, kExitOk) << err;
  EXPECT_EQ(command.back(), "-dash");
}

// --intrinsics, as tum-play and bag-import read it: absent is none; fx, fy > 0 and finite values.
TEST(Cli, IntrinsicsOptionGivesACameraOrNamesTheOption) {
  EXPECT_FALSE(intrinsics_option({}));
  const auto c = intrinsics_option({500, 510, 319.5, 239.5});
  ASSERT_TRUE(c);
  EXPECT_EQ(c->fx, 500);
  EXPECT_EQ(c->fy, 510);
  EXPECT_EQ(c->cx, 319.5);
  EXPECT_EQ(c->cy, 239.5);
  for (const std::vector<double>& bad : std::vector<std::vector<double>>{
           {0, 500, 1, 1}, {500, -1, 1, 1}, {500, 500, std::nan(""), 1}, {500, 500, 1, std::numeric_limits<double>::infinity()}, {500, 500, 1}}) {
    try {
      intrinsics_option(bad);
      ADD_FAILURE() << "accepted " << bad.size() << " values";
    } catch (const CLI::ValidationError& e) {
      EXPECT_NE(std::string(e.what()).find("--intrinsics"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace kestrel::cli
