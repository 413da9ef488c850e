#pragma once
// Ctrl-C for tools that run without a Node (writing a log, replaying, launching): SIGINT,
// SIGTERM and SIGHUP set a flag that the tool's loop checks between items, so it stops
// cleanly (files closed, children stopped) instead of dying in the middle of a write.
// Processes built on transport::Node get the same behaviour from the Node.
//
// Invariant: the handlers only store to lock-free atomics (async-signal-safe), and are
// installed without SA_RESTART so that a blocking wait returns early and sees the flag.

#include <atomic>

namespace kestrel {

/// Installs the handlers (once; later calls do nothing) and returns the flag, which turns
/// true when one of the signals arrives.
const std::atomic<bool>& catch_interrupts();

/// True once SIGINT, SIGTERM or SIGHUP arrived (after catch_interrupts()).
bool interrupted();

/// The signal that arrived last (0: none), e.g. to exit kExitInterrupted on SIGINT only.
int interrupt_signal();

}  // namespace kestrel
