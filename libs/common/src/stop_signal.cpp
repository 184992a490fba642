// The stop flag behind install_stop_handlers().
#include "fahr/common/stop_signal.h"

#include <csignal>

namespace fahr::common {
namespace {
volatile std::sig_atomic_t g_stop_requested = 0;
extern "C" void on_stop_signal(int) {
  g_stop_requested = 1;
}
}  // namespace

void install_stop_handlers() {
  std::signal(SIGINT, on_stop_signal);
  std::signal(SIGTERM, on_stop_signal);
}

bool stop_requested() {
  return g_stop_requested != 0;
}

}  // namespace fahr::common
