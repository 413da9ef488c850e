#pragma once
// Running a shell script as root of a private network namespace whose loopback carries
// multicast, so that LCM traffic between test processes never leaves it (DESIGN.md).

#include <string>

#include "test/support/test_support.h"

namespace kestrel::test {

inline RunResult run_isolated(const std::string& script, double timeout_s = 120.0) {
  return run({"unshare", "-n", "sh", "-c",
              "ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo && " +
                  script},
             timeout_s);
}

/// `s` in single quotes for sh.
inline std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace kestrel::test
