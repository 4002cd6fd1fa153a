#pragma once
// Ctrl-C and `kill` during a long command: the first SIGINT or SIGTERM only raises a flag that
// the refinement polls between vertex blocks, so the command stops within a block, writes
// nothing half-done and exits with kInterrupted; a second signal ends the process at once.

#include <atomic>

namespace mvflow::cli {

//! Installs the SIGINT and SIGTERM handlers. Only commands that poll interrupt_requested() call
//! it (refine, batch); the others keep the default: a signal ends them at once.
void install_interrupt_handlers();

//! Set by the first SIGINT or SIGTERM; pass it as RefineControl::cancel.
const std::atomic<bool>& interrupt_requested();

}  // namespace mvflow::cli
