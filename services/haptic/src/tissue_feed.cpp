// The state thread of the real-time haptic service (see tissue_feed.h).
#include "fahr/haptic_service/tissue_feed.h"

#include <algorithm>
#include <chrono>

#include "fahr/common/clock.h"
#include "fahr/haptic_service/haptic_loop.h"

namespace fahr::haptic_service {

TissueFeed::TissueFeed(common::Participant& participant, const HapticSetup& setup)
    : digest_(setup),
      buffer_([this] { return digest_.make_snapshot(); }),
      newest_(setup.bodies.size(), nullptr) {
  // One FEM at a time: another writer refused while it has sent within 1 s
  // (the tongue is already lost after 50 ms); a restarted FEM is followed
  // once the first has been silent that long. A state that does not fit the
  // mesh is refused before it can become the source, and one naming no body
  // of the scene goes to the first body's reader, to be refused there.
  const std::vector<std::uint32_t> ids = body_ids(setup);
  for (std::size_t b = 0; b < ids.size(); ++b) {
    states_.push_back(std::make_unique<common::Subscriber<msg::DeformationState>>(
        participant,
        common::Admission<msg::DeformationState>{
            .takeover = std::chrono::seconds(1),
            .valid = [this](const msg::DeformationState& s) { return digest_.plausible(s); },
            .counts = admission_,
            .wanted = common::body_instance<msg::DeformationState>(ids, b, /*strays=*/true)}));
  }
  thread_ = std::thread([this] { run(); });
}

TissueFeed::~TissueFeed() {
  stop_.store(true, std::memory_order_relaxed);
  thread_.join();
}

void TissueFeed::run() {
  using namespace std::chrono_literals;
  std::uint64_t seen = 0;
  while (!stop_.load(std::memory_order_relaxed)) {
    // 50 ms: short enough to notice the stop, long enough not to spin. The
    // FEM writes its bodies' states in order: the last body's marks a period.
    seen = states_.back()->wait_for_samples(seen, 50ms);
    bool fresh = false;
    for (std::size_t b = 0; b < states_.size(); ++b) {
      if (!states_[b]->fetch_newest()) continue;
      newest_[b] = &states_[b]->newest();
      fresh = true;
    }
    if (!fresh) continue;
    // Every body heard from before the first digest.
    if (std::find(newest_.begin(), newest_.end(), nullptr) != newest_.end()) continue;
    TissueSnapshot& next = buffer_.back();
    if (!digest_.digest(newest_, next)) {
      metrics_.bad_states.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    buffer_.publish();
    last_state_ns_.store(common::monotonic_now_ns(), std::memory_order_release);
    metrics_.fem_states.fetch_add(1, std::memory_order_relaxed);
    metrics_.obstacle_contacts.store(static_cast<std::uint32_t>(next.obstacle_count),
                                     std::memory_order_relaxed);
    if (next.obstacle_overflow) metrics_.obstacle_overflows.fetch_add(1, std::memory_order_relaxed);
    metrics_.free_centres.store(next.have_free_centres, std::memory_order_relaxed);
    if (next.digest_us > metrics_.digest_us_max.load(std::memory_order_relaxed)) {
      metrics_.digest_us_max.store(next.digest_us, std::memory_order_relaxed);
    }
    if (next.digest_us > metrics_.digest_us_peak.load(std::memory_order_relaxed)) {
      metrics_.digest_us_peak.store(next.digest_us, std::memory_order_relaxed);
    }
  }
}

void TissueFeed::append_metrics(std::vector<std::pair<std::string, double>>& out) {
  const auto get = [](const auto& a) {
    return static_cast<double>(a.load(std::memory_order_relaxed));
  };
  out.emplace_back("fem_states", get(metrics_.fem_states));
  out.emplace_back("bad_states", get(metrics_.bad_states));
  common::append_admission_metrics(*admission_, "states", out);
  out.emplace_back("obstacle_contacts", get(metrics_.obstacle_contacts));
  out.emplace_back("obstacle_overflows", get(metrics_.obstacle_overflows));
  out.emplace_back("free_centres",
                   metrics_.free_centres.load(std::memory_order_relaxed) ? 1.0 : 0.0);
  out.emplace_back("digest_us_max",
                   metrics_.digest_us_max.exchange(0.0, std::memory_order_relaxed));
}

}  // namespace fahr::haptic_service
