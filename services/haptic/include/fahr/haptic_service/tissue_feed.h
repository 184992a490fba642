// Real time: a thread of its own digests every new DeformationState (with
// several deformable bodies, each body's newest: one reader per body, the
// FEM writing them in the scene's order) into a TissueSnapshot and hands it
// to the tick through a triple buffer. The tick
// takes the newest snapshot without waiting; a digest (~1 ms on the neonatal
// tongue) never delays a force. Lockstep digests inline instead
// (haptic_service_main.cpp), where reproducibility matters, not latency.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "deformation_state.h"
#include "fahr/common/participant.h"
#include "fahr/common/subscriber.h"
#include "fahr/common/triple_buffer.h"
#include "fahr/haptic_service/haptic_setup.h"
#include "fahr/haptic_service/tissue_snapshot.h"

namespace fahr::haptic_service {

// Read by the reporter thread (relaxed atomics, independent values).
struct FeedMetrics {
  std::atomic<std::uint64_t> fem_states{0};         // digested
  std::atomic<std::uint64_t> bad_states{0};         // wrong size or non-finite: ignored
  std::atomic<std::uint32_t> obstacle_contacts{0};  // tongue vs anatomy, newest state
  std::atomic<std::uint64_t> obstacle_overflows{0};
  std::atomic<bool> free_centres{false};    // the newest state carried free-motion centres
  std::atomic<double> digest_us_max{0.0};   // since the last report, us
  std::atomic<double> digest_us_peak{0.0};  // whole run, us
};

class TissueFeed {
 public:
  // Subscribes to DeformationState on `participant` and starts the thread.
  TissueFeed(common::Participant& participant, const HapticSetup& setup);
  ~TissueFeed();
  TissueFeed(const TissueFeed&) = delete;
  TissueFeed& operator=(const TissueFeed&) = delete;

  // Tick thread: the newest snapshot (the rest state before the first).
  // Wait-free; the reference stays valid until the next call.
  const TissueSnapshot& newest() {
    buffer_.fetch();
    return buffer_.front();
  }

  // Monotonic time the newest usable state was digested, ns (0: none yet).
  // Any thread; the tick compares it with its clock to see the FEM gone
  // (haptic_loop.h kTissueLossTimeout).
  std::int64_t last_state_ns() const { return last_state_ns_.load(std::memory_order_acquire); }

  const FeedMetrics& metrics() const { return metrics_; }
  // DeformationStates refused before the digest (another writer, out of
  // order), all bodies'.
  const common::AdmissionCounts& admission() const { return *admission_; }
  // Also resets the per-report maximum (reporter thread).
  void append_metrics(std::vector<std::pair<std::string, double>>& out);

 private:
  void run();

  TissueDigest digest_;
  common::TripleBuffer<TissueSnapshot> buffer_;
  std::shared_ptr<common::AdmissionCounts> admission_ = std::make_shared<common::AdmissionCounts>();
  std::vector<std::unique_ptr<common::Subscriber<msg::DeformationState>>> states_;  // per body
  std::vector<const msg::DeformationState*> newest_;  // per body, null until its first
  FeedMetrics metrics_;
  std::atomic<std::int64_t> last_state_ns_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;  // started by the constructor once everything above exists
};

}  // namespace fahr::haptic_service
