// Opt-in real-time scheduling for a service's tick thread: SCHED_FIFO at a
// given priority. Needs CAP_SYS_NICE (or an rtprio limit); without it the
// thread keeps the normal scheduler and the caller says so once, at start.
#pragma once

#include <string>

namespace fahr::common {

// Puts the calling thread under SCHED_FIFO at `priority` (1-99). Returns an
// empty string on success, otherwise why not (the thread is unchanged).
std::string request_realtime_priority(int priority);

}  // namespace fahr::common
