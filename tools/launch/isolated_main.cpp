// kestrel-isolated [--] CMD ARGS...: runs CMD in a private network namespace whose loopback
// carries multicast (tools/launch/isolation.h), so LCM processes started by CMD talk to each
// other and to nothing else. The exit status is CMD's (it replaces this process).

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/error.h"
#include "tools/launch/isolation.h"

int main(int argc, char** argv) {
  kestrel::cli::App app("isolated",
                        "Runs a command in a private network namespace: loopback only, up, with "
                        "multicast and the route 224.0.0.0/4 dev lo, so that LCM works between "
                        "the processes it starts and never leaves the host. Exit status: the "
                        "command's; 4 if no namespace can be made; 126/127 if the command "
                        "cannot be run.");
  // Everything from the first argument that is not an option of ours belongs to CMD.
  app.prefix_command();
  app.footer("Usage: kestrel-isolated [OPTIONS] [--] CMD [ARGS...]");
  return app.run(argc, argv, [&] {
    std::vector<std::string> command = app.remaining();
    if (!command.empty() && command.front() == "--") command.erase(command.begin());
    if (command.empty()) throw CLI::RequiredError("CMD");
    try {
      const auto method = kestrel::launch::enter_private_network();
      spdlog::debug("isolated in a {}", kestrel::launch::to_string(method));
    } catch (const kestrel::launch::IsolationError& e) {
      spdlog::error("{}", e.what());
      return static_cast<int>(kestrel::kExitUnavailable);
    }
    std::vector<char*> args;
    for (auto& a : command) args.push_back(a.data());
    args.push_back(nullptr);
    ::execvp(args[0], args.data());
    const int err = errno;
    spdlog::error("cannot run '{}': {}", command[0], std::strerror(err));
    return err == ENOENT ? 127 : 126;  // the shell's conventions for "not found" / "not runnable"
  });
}
