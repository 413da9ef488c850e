#pragma once
// A private network namespace for running kestrel processes together: only a loopback
// interface, up, multicast-capable, with the route 224.0.0.0/4 through it. LCM's UDP
// multicast then works between the processes inside and nothing reaches a real interface.
// Used by kestrel-isolated, `kestrel-launch --isolated` and the multi-process tests.
//
// Invariants: on success the calling process (and every child it starts afterwards) sees no
// interface but `lo`; on failure nothing has changed, or the process is in a namespace it
// cannot use and the caller must exit (the error says which).

#include <stdexcept>
#include <string>

namespace kestrel::launch {

/// Why the private network could not be made; what() is one line.
class IsolationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class IsolationMethod {
  kNetworkNamespace,      ///< unshare(CLONE_NEWNET): root or CAP_SYS_ADMIN
  kUserNetworkNamespace,  ///< unshare(CLONE_NEWUSER | CLONE_NEWNET), same uid/gid mapped
};

/// Moves the calling process into a new network namespace and configures its loopback as
/// above. Tries a plain network namespace first, then an unprivileged user namespace.
/// Must be called before the process starts any thread (user namespaces require it, and a
/// network namespace only applies to the calling thread). Throws IsolationError.
IsolationMethod enter_private_network();

/// Two private networks, each as enter_private_network() makes one, for the two sides of
/// `kestrel launch --link`: the first (onboard) and the second (offboard) as open fds of
/// their namespaces (close-on-exec; another process reaches one as /proc/PID/fd/FD). The
/// calling process is left in the second. Same preconditions; throws IsolationError.
struct PrivateNetworkPair {
  int onboard_fd = -1;
  int offboard_fd = -1;
  IsolationMethod method = IsolationMethod::kNetworkNamespace;
};
PrivateNetworkPair enter_private_network_pair();

/// "network namespace" or "user + network namespace".
std::string to_string(IsolationMethod method);

}  // namespace kestrel::launch
