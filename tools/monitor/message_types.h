#pragma once
// The kestrel message types the monitor can check, and which channel carries which type.
//
// A message is checked by decoding it completely with its lcm-gen type (fingerprint, every
// field, no bytes left over). Channels the table does not name are identified by their
// fingerprint (the first 8 bytes of every LCM message), the way lcm-spy does, so a renamed
// channel such as CAMERA_RGBD_Z is still checked; what matches no kestrel type is counted
// as raw bytes.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace kestrel::monitor {

struct MessageType {
  std::string name;     ///< lcm-gen type name without the package, e.g. "imu_t"
  int64_t fingerprint;  ///< as written in the first 8 bytes of a message
  /// Decodes the bytes; throws InputError naming `channel` if they are not this type.
  std::function<void(const void* data, size_t size, const std::string& channel)> check;
};

/// Every type in lcmtypes/.
const std::vector<MessageType>& kestrel_types();
/// By name, with or without the "kestrel." package; nullptr if unknown.
const MessageType* find_type(const std::string& name);
/// The kestrel type whose fingerprint starts `data`; nullptr if none.
const MessageType* identify(const void* data, size_t size);

/// The channels of README "Channels" (common/transport/channels.h) and their types.
std::map<std::string, const MessageType*> default_channel_types();

/// Parses "CHANNEL=TYPE"; throws std::invalid_argument naming what is wrong.
std::pair<std::string, const MessageType*> parse_channel_type(const std::string& spec);

}  // namespace kestrel::monitor
