#include "tools/link/lcm_datagram.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace kestrel::link {
namespace {

constexpr uint32_t kMagicShort = 0x4c433032;  // "LC02"
constexpr uint32_t kMagicFragment = 0x4c433033;  // "LC03"
constexpr size_t kShortHeader = 8;
constexpr size_t kFragmentHeader = 20;
constexpr size_t kMaxChannel = 63;

uint32_t be32(const uint8_t* p) {
  return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
}
uint16_t be16(const uint8_t* p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }

bool read_channel(const uint8_t* data, size_t size, size_t begin, DatagramHeader& h) {
  const size_t limit = std::min(size, begin + kMaxChannel + 1);
  const void* nul = std::memchr(data + begin, 0, limit - begin);
  if (nul == nullptr) return false;
  h.channel_begin = begin;
  h.channel_end = static_cast<size_t>(static_cast<const uint8_t*>(nul) - data);
  h.channel.assign(reinterpret_cast<const char*>(data + begin), h.channel_end - begin);
  return !h.channel.empty();
}

}  // namespace

std::optional<DatagramHeader> parse_datagram(const uint8_t* data, size_t size) {
  if (size < kShortHeader) return std::nullopt;
  DatagramHeader h;
  const uint32_t magic = be32(data);
  h.seqno = be32(data + 4);
  if (magic == kMagicShort) {
    if (!read_channel(data, size, kShortHeader, h)) return std::nullopt;
    return h;
  }
  if (magic != kMagicFragment || size < kFragmentHeader) return std::nullopt;
  h.fragmented = true;
  h.fragment_no = be16(data + 16);
  h.fragments = be16(data + 18);
  if (h.fragments == 0 || h.fragment_no >= h.fragments) return std::nullopt;
  if (h.fragment_no == 0 && !read_channel(data, size, kFragmentHeader, h)) return std::nullopt;
  return h;
}

std::vector<uint8_t> rename_channel(const uint8_t* data, size_t size, const DatagramHeader& h,
                                    const std::string& channel) {
  std::vector<uint8_t> out;
  out.reserve(size + channel.size());
  out.insert(out.end(), data, data + h.channel_begin);
  out.insert(out.end(), channel.begin(), channel.end());
  out.insert(out.end(), data + h.channel_end, data + size);  // from the NUL on
  return out;
}

Router::Router(const std::vector<std::string>& rules) {
  for (const auto& rule : rules) {
    const size_t arrow = rule.find('>');
    const std::string from = rule.substr(0, arrow);
    const std::string to = arrow == std::string::npos ? from : rule.substr(arrow + 1);
    if (from.empty() || to.empty() || from.size() > kMaxChannel || to.size() > kMaxChannel)
      throw std::invalid_argument("bad channel rule '" + rule + "' (NAME or FROM>TO)");
    if (!rules_.emplace(from, to).second)
      throw std::invalid_argument("channel " + from + " is named twice");
  }
}

std::string Router::far_name(const std::string& channel) const {
  const auto it = rules_.find(channel);
  return it == rules_.end() ? std::string() : it->second;
}

std::optional<std::vector<uint8_t>> Router::route(uint64_t sender, const uint8_t* data, size_t size) {
  const auto h = parse_datagram(data, size);
  if (!h) {
    ++malformed_;
    return std::nullopt;
  }
  std::string channel = h->channel;
  if (h->fragmented) {
    if (h->fragment_no == 0) {
      in_flight_[sender] = {h->seqno, rules_.count(channel) ? channel : std::string()};
    } else {
      const auto it = in_flight_.find(sender);
      if (it == in_flight_.end() || it->second.seqno != h->seqno) {
        ++orphans_;
        return std::nullopt;
      }
      channel = it->second.channel;
      if (h->fragment_no + 1 == h->fragments) in_flight_.erase(it);
    }
  }
  const auto rule = rules_.find(channel);
  if (channel.empty() || rule == rules_.end()) return std::nullopt;
  ++forwarded_[channel];
  forwarded_bytes_[channel] += static_cast<int64_t>(size);
  if (h->channel.empty() || rule->second == channel) return std::vector<uint8_t>(data, data + size);
  return rename_channel(data, size, *h, rule->second);
}

}  // namespace kestrel::link
