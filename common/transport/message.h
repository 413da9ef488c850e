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
    throw InputError(what + ": " + std::to_string(size) + " bytes are not a valid " +
                     Msg::getTypeName() + " (other type, truncated or corrupt)");
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
