#include "core/signals.h"

#include <csignal>
#include <string>

#include "core/errors.h"

namespace raysift {
namespace {

std::atomic<bool> g_cancelled{false};
std::atomic<int> g_signal{0};
static_assert(std::atomic<bool>::is_always_lock_free && std::atomic<int>::is_always_lock_free,
              "the handler may only touch lock-free atomics");

extern "C" void on_cancel_signal(int signo) {
  g_signal.store(signo);
  g_cancelled.store(true);
}

}  // namespace

void install_cancel_handlers() {
  struct sigaction action {};
  action.sa_handler = on_cancel_signal;
  sigemptyset(&action.sa_mask);
  // SA_RESTART: reads and writes in progress finish, the stage notices at its next poll.
  // SA_RESETHAND: a second Ctrl-C gets the default action and ends a stage that never polls.
  action.sa_flags = SA_RESTART | SA_RESETHAND;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

const std::atomic<bool>& cancel_flag() { return g_cancelled; }

int cancel_signal() { return g_signal.load(); }

void throw_if_cancelled() {
  if (!g_cancelled.load(std::memory_order_relaxed)) return;
  throw Cancelled(std::string("interrupted by ") + (g_signal.load() == SIGTERM ? "SIGTERM" : "SIGINT"));
}

}  // namespace raysift
