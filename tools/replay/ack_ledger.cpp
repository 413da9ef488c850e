#include "tools/replay/ack_ledger.h"

#include <algorithm>
#include <iterator>

namespace kestrel::replay {

AckLedger::AckLedger(ConsumerMap consumers, std::function<bool(const std::string&)> is_recorded)
    : consumers_(std::move(consumers)), is_recorded_(std::move(is_recorded)) {}

void AckLedger::expect_consumers(const std::string& channel) {
  const auto it = consumers_.find(channel);
  if (it == consumers_.end()) return;
  for (const auto& process : it->second) ++acks_[{process, channel}];
}

void AckLedger::publish(const std::string& channel) { expect_consumers(channel); }

void AckLedger::acknowledge(const std::string& process, const std::string& channel,
                            const std::vector<std::string>& outputs) {
  --acks_[{process, channel}];
  announce(outputs);
}

void AckLedger::announce(const std::vector<std::string>& outputs) {
  for (const auto& out : outputs) {
    expect_consumers(out);
    if (is_recorded_(out)) ++messages_[out];
  }
}

void AckLedger::forget(const std::string& process) {
  for (auto it = acks_.begin(); it != acks_.end();) it = it->first.first == process ? acks_.erase(it) : std::next(it);
  for (auto& [channel, names] : consumers_) names.erase(std::remove(names.begin(), names.end(), process), names.end());
}

void AckLedger::receive(const std::string& channel) { --messages_[channel]; }

bool AckLedger::settled() const {
  for (const auto& [key, n] : acks_)
    if (n != 0) return false;
  for (const auto& [channel, n] : messages_)
    if (n > 0) return false;
  return true;
}

int64_t AckLedger::awaited_acks() const {
  int64_t total = 0;
  for (const auto& [key, n] : acks_)
    if (n > 0) total += n;
  return total;
}

bool AckLedger::owes(const std::string& process) const {
  for (const auto& [key, n] : acks_)
    if (key.first == process && n > 0) return true;
  return false;
}

std::vector<AckLedger::Owed> AckLedger::outstanding() const {
  std::vector<Owed> out;
  for (const auto& [key, n] : acks_)
    if (n != 0) out.push_back({key.first, key.second, n});
  for (const auto& [channel, n] : messages_)
    if (n > 0) out.push_back({"", channel, n});
  return out;
}

int64_t AckLedger::finish_event() {
  int64_t unannounced = 0;
  for (const auto& [channel, n] : messages_)
    if (n < 0) unannounced -= n;
  acks_.clear();
  messages_.clear();
  return unannounced;
}

std::string explain(const AckLedger::Owed& o) {
  const std::string n = std::to_string(o.count > 0 ? o.count : -o.count);
  if (o.process.empty())
    return n + " message(s) on " + o.channel + " announced in acknowledgements but never received";
  if (o.count > 0)
    return o.process + " did not acknowledge " + n + " " + o.channel + " input(s)";
  return o.process + " acknowledged " + n + " " + o.channel +
         " input(s) the replay did not send or announce (a free-running source, or a process "
         "outside the discovered set, publishing " + o.channel + "?)";
}

}  // namespace kestrel::replay
