// SCHED_FIFO for the calling thread (see realtime.h).
#include "fahr/common/realtime.h"

#include <pthread.h>
#include <sched.h>

#include <cstring>

namespace fahr::common {

std::string request_realtime_priority(int priority) {
  const int lowest = sched_get_priority_min(SCHED_FIFO);
  const int highest = sched_get_priority_max(SCHED_FIFO);
  if (priority < lowest || priority > highest) {
    return "priority " + std::to_string(priority) + " is outside SCHED_FIFO's [" +
           std::to_string(lowest) + ", " + std::to_string(highest) + "]";
  }
  sched_param param{};
  param.sched_priority = priority;
  if (const int error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param); error != 0) {
    return std::string("SCHED_FIFO refused: ") + std::strerror(error) +
           " (needs CAP_SYS_NICE or an rtprio limit, e.g. in /etc/security/limits.conf)";
  }
  return {};
}

}  // namespace fahr::common
