#pragma once
// Encoding and checked decoding of lcm-gen message types.

#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/error.h"

namespace kestrel::transport {

/// The bytes of `msg` as LCM puts them on the wire.
template <class Msg>
std::vector<uint8_t> encode_message(const Msg& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

/// Decodes exactly `size` bytes as a Msg. Throws InputError naming `what` (a channel or file)
/// when the bytes are of another type (fingerprint mismatch), truncated, corrupt, or longer
/// than the message.
template <class Msg>
Msg decode_message(const void* data, size_t size, const std::string& what) {
  Msg msg;
  const int used = size > static_cast<size_t>(INT32_MAX)
                       ? -1
                       : msg.decode(data, 0, static_cast<int>(size));
  if (used < 0) {
    // LCM starts a message with its type's fingerprint (8 bytes, big-endian), a hash of the
    // type's fields: tell a message of another type, or of this type as another version of
    // kestrel defined it (a log recorded before a message changed), from a damaged one.
    uint64_t fingerprint = 0;
    for (size_t i = 0; i < 8 && size >= 8; ++i) fingerprint = (fingerprint << 8) | static_cast<const uint8_t*>(data)[i];
    const std::string bytes = what + ": " + std::to_string(size) + " bytes";
    if (size < 8) throw InputError(bytes + " are too short for any message");
    if (fingerprint != static_cast<uint64_t>(Msg::getHash())) {
      throw InputError(bytes + " are not of type " + Msg::getTypeName() +
                       " (another fingerprint: another message type, or a version of it from an "
                       "older or newer kestrel, e.g. a log recorded before the message changed)");
    }
    throw InputError(bytes + " are a truncated or corrupt " + Msg::getTypeName() + " message");
  }
  if (static_cast<size_t>(used) != size) {
    throw InputError(what + ": " + Msg::getTypeName() + " of " + std::to_string(used) +
                     " bytes followed by " + std::to_string(size - used) + " extra bytes");
  }
  return msg;
}

template <class Msg, class = void>
struct has_utime : std::false_type {};
template <class Msg>
struct has_utime<Msg, std::void_t<decltype(std::declval<const Msg&>().utime)>> : std::true_type {};

/// The sensor time of a message: its `utime` field, or 0 for types without one.
template <class Msg>
int64_t message_utime(const Msg& msg) {
  if constexpr (has_utime<Msg>::value) {
    return msg.utime;
  } else {
    return 0;
  }
}

}  // namespace kestrel::transport
