#pragma once
/// \file Ctrl-C and `kill`: SIGINT/SIGTERM set one process-wide cancel flag that long stages poll (their
/// `cancel` option, or throw_if_cancelled() between chunks); the stage throws Cancelled, the staged outputs
/// are removed while the exception unwinds, and the app exits 128 + signal. The flag is the one mutable global
/// of the project: a signal handler can reach nothing else. A second signal kills the process at once (the
/// default action), for a stage that does not poll.
#include <atomic>

namespace raysift {

/// Installs the SIGINT and SIGTERM handlers (idempotent). Only apps call this.
void install_cancel_handlers();

/// Becomes true on the first SIGINT/SIGTERM; pass its address as a stage's `cancel` option.
const std::atomic<bool>& cancel_flag();

/// The signal that set the flag (SIGINT = 2, SIGTERM = 15), or 0 if none arrived.
int cancel_signal();

/// \throw Cancelled ("interrupted by SIGINT") once a signal has arrived; otherwise does nothing.
void throw_if_cancelled();

}  // namespace raysift
