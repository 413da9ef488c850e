#pragma once
// LCM's UDP datagrams as kestrel-link sees them, and which of them cross the link. No
// sockets: bytes in, a decision out.
//
// LCM (udpm) sends a message of up to about 64 kB as one datagram, "LC02" (magic, sequence
// number, the channel's name ending in NUL, the payload), and a bigger one as several, "LC03"
// (magic, sequence number, message size, fragment offset, fragment number, fragment count;
// the channel's name only in fragment 0), all big-endian. A receiver puts the fragments
// together per sender address and sequence number, starting from fragment 0, and drops the
// message if any fragment is missing; so a link that loses one fragment loses the message.
//
// Router invariants: a datagram is forwarded only if its channel is one of the rules' (the
// channel of a fragment after fragment 0 is that of fragment 0 of the same sender and
// sequence number; a fragment whose fragment 0 was not seen is not forwarded); a forwarded
// datagram differs from the one received only in the channel's name, when a rule renames it;
// malformed datagrams are counted and never forwarded.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace kestrel::link {

struct DatagramHeader {
  bool fragmented = false;
  uint32_t seqno = 0;
  uint16_t fragment_no = 0;        ///< fragmented only
  uint16_t fragments = 1;          ///< fragmented only
  std::string channel;             ///< empty for a fragment after the first
  size_t channel_begin = 0, channel_end = 0;  ///< the name's bytes (the NUL is at channel_end)
};

/// The header of an LCM datagram, or nullopt if it is not one (bad magic, too short, a
/// channel's name without its NUL or longer than LCM's 63 characters).
std::optional<DatagramHeader> parse_datagram(const uint8_t* data, size_t size);

/// The datagram with its channel's name replaced by `channel` (a datagram that names a
/// channel: short, or fragment 0).
std::vector<uint8_t> rename_channel(const uint8_t* data, size_t size, const DatagramHeader& header,
                                    const std::string& channel);

/// One direction's channel rules: "NAME" forwards NAME as it is, "FROM>TO" forwards FROM
/// and renames it TO on the far side.
class Router {
 public:
  /// Throws std::invalid_argument for an empty rule, a rule with an empty side, or a channel
  /// named twice.
  explicit Router(const std::vector<std::string>& rules);

  /// What to send on for a datagram received from `sender` (any key that tells LCM's senders
  /// apart: their address and port), or nullopt if it does not cross.
  std::optional<std::vector<uint8_t>> route(uint64_t sender, const uint8_t* data, size_t size);

  int64_t malformed() const { return malformed_; }
  int64_t orphan_fragments() const { return orphans_; }
  /// The channels that crossed and how many datagrams of each (by the channel's name here).
  const std::map<std::string, int64_t>& forwarded() const { return forwarded_; }
  /// ... and their bytes (as received).
  const std::map<std::string, int64_t>& forwarded_bytes() const { return forwarded_bytes_; }
  /// The far side's name of `channel` if it crosses ("" if not).
  std::string far_name(const std::string& channel) const;

 private:
  struct InFlight {
    uint32_t seqno = 0;
    std::string channel;  ///< empty: this message does not cross
  };
  std::map<std::string, std::string> rules_;  ///< near name -> far name
  std::map<uint64_t, InFlight> in_flight_;    ///< per sender: its fragmented message
  std::map<std::string, int64_t> forwarded_, forwarded_bytes_;
  int64_t malformed_ = 0, orphans_ = 0;
};

}  // namespace kestrel::link
