#pragma once
// The accounting at the heart of lock-step replay: what is still in flight after one log
// event was published, and when it is all done. Knows nothing of LCM.
//
// Publishing an event on channel C expects one acknowledgement from each consumer of C.
// An acknowledgement (P, C, outputs) settles one of P's C inputs and, for each output
// channel X it lists, expects one acknowledgement from each consumer of X and, when X is
// recorded, one message on X. The event is settled when every expectation is met.
//
// Counts are signed and kept per (process, channel): messages from different senders may
// overtake each other (P's consumer Q can acknowledge X before P's own acknowledgement that
// announced X arrives), so a count may go below zero for a moment. Settled means every count
// is zero (acknowledgements) and no recorded channel is owed a message.

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "tools/replay/process_table.h"

namespace kestrel::replay {

class AckLedger {
 public:
  /// `is_recorded(channel)`: whether messages on it are collected (so must be received
  /// before the event is settled).
  AckLedger(ConsumerMap consumers, std::function<bool(const std::string&)> is_recorded);

  /// The replay published one message on `channel`.
  void publish(const std::string& channel);
  /// `process` finished one input on `channel` and published on each of `outputs`.
  void acknowledge(const std::string& process, const std::string& channel,
                   const std::vector<std::string>& outputs);
  /// A process outside the consumer map (one that joined during the event) finished an
  /// input and published on each of `outputs`: nothing was owed by it, but its outputs are
  /// inputs of the others, whose acknowledgements are awaited.
  void announce(const std::vector<std::string>& outputs);
  /// `process` left: whatever it still owes is written off.
  void forget(const std::string& process);
  /// A message arrived on a recorded channel.
  void receive(const std::string& channel);

  bool settled() const;
  /// Acknowledgements still awaited, summed over processes.
  int64_t awaited_acks() const;
  /// One count that is not settled.
  struct Owed {
    std::string process;  ///< empty for a message owed on a recorded channel
    std::string channel;
    int64_t count;        ///< > 0: still owed; < 0: more than expected arrived
  };
  /// Every count that keeps the event from being settled, and every one below zero.
  std::vector<Owed> outstanding() const;

  /// Closes the event: returns the number of messages received on recorded channels beyond
  /// those announced (published outside any handler), and clears every count.
  int64_t finish_event();
  /// True if `process` owes an acknowledgement now.
  bool owes(const std::string& process) const;

 private:
  void expect_consumers(const std::string& channel);
  ConsumerMap consumers_;
  std::function<bool(const std::string&)> is_recorded_;
  std::map<std::pair<std::string, std::string>, int64_t> acks_;  // (process, channel) -> owed
  std::map<std::string, int64_t> messages_;                      // channel -> owed
};

/// One line explaining an outstanding item for an error message.
std::string explain(const AckLedger::Owed& owed);

}  // namespace kestrel::replay
