#include "tools/interrupt.h"

#include <csignal>

namespace mvflow::cli {

namespace {

std::atomic<bool> requested{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the flag is set from a signal handler");

extern "C" void on_interrupt(int signal_number) {
  if (requested.exchange(true)) {  // the second one: the user insists
    std::signal(signal_number, SIG_DFL);
    std::raise(signal_number);
  }
}

}  // namespace

void install_interrupt_handlers() {
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
}

const std::atomic<bool>& interrupt_requested() { return requested; }

}  // namespace mvflow::cli
