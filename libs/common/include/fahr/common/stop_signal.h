// SIGINT and SIGTERM ask a service to stop: its loop finishes the current
// tick, the service publishes its final report and exits cleanly, so a
// launcher's Ctrl-C never loses the last status of a run.
#pragma once

namespace fahr::common {

// Installs the handlers (call once, early in main).
void install_stop_handlers();
// True once SIGINT or SIGTERM has arrived. Async-signal-safe to set, a
// lock-free read to test: fine in a 1 kHz loop.
bool stop_requested();

}  // namespace fahr::common
