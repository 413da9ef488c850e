// Every process started where LCM cannot work (a network namespace whose loopback is down, so
// there is no multicast route) exits with code 4 and one line naming the LCM URL, instead of
// running deaf or dying on an exception.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "test/support/test_support.h"

namespace kestrel::test {
namespace {

TEST(Unavailable, EveryProcessExitsFourNamingLcmWhenThereIsNoNetwork) {
  if (!can_isolate_network()) KESTREL_SKIP_ENVIRONMENT() << "cannot create a network namespace here (needs root or user namespaces)";
  struct Case {
    std::string tool;
    std::vector<std::string> args;
  };
  const Case cases[] = {{"vo", {}},      {"estimator", {}}, {"slam", {}},       {"mapper", {}},
                        {"planner", {}}, {"follow", {}},    {"rgbd-codec", {}}, {"monitor", {}},
                        {"station", {}},
                        {"sim", {"--world", "room", "--duration", "1"}}};
  int ran = 0;
  for (const Case& c : cases) {
    const std::filesystem::path bin = tool(c.tool);
    if (!std::filesystem::exists(bin)) continue;  // a component not built in this configuration
    std::vector<std::string> argv{"unshare", "--net", bin.string()};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    const RunResult r = run(argv, 60.0);
    EXPECT_EQ(r.exit_code, 4) << c.tool << ": " << r.err;
    EXPECT_NE(r.err.find("cannot start LCM on 'udpm://"), std::string::npos) << c.tool << ": " << r.err;
    ++ran;
  }
  EXPECT_GE(ran, 5) << "too few processes are built to test";
}

}  // namespace
}  // namespace kestrel::test
