// A typed reader. Every sample lands in a LatestSample triple buffer (the
// newest, for loops that poll without blocking or allocating) and, if set,
// in a handler called on the vendor thread (for consumers that need every
// sample: loggers, lockstep inputs). An Admission, if given, decides on the
// vendor thread which samples get in at all (one source, in order, valid),
// so a refused sample never displaces the newest good one.
#pragma once

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fahr/common/clock.h"
#include "fahr/common/latest_sample.h"
#include "fahr/common/participant.h"
#include "fahr/common/topics.h"

namespace fahr::common {

struct AdmissionCounts {
  std::atomic<std::uint64_t> foreign{0};       // another writer while the source lives
  std::atomic<std::uint64_t> out_of_order{0};  // the source's sequence did not advance
  std::atomic<std::uint64_t> invalid{0};       // failed Admission::valid
  std::atomic<std::uint64_t> source_changes{0};
};

// "<prefix>_refused_foreign", "_refused_order", "_refused_invalid" for a
// ServiceStatus.
void append_admission_metrics(const AdmissionCounts& counts, const std::string& prefix,
                              std::vector<std::pair<std::string, double>>& out);
// "foreign N, out of order N, invalid N, source changes N" for a service's
// last lines.
std::string admission_summary(const AdmissionCounts& counts);

// Which samples a Subscriber lets in. The streams of a station have one
// writer each; anyone else on the domain is refused (docs/design/faults.md,
// "Hostile samples").
template <class T>
struct Admission {
  // The first writer heard is the source. A sample of another writer is
  // refused while the source has sent within this time; after it, the next
  // writer heard becomes the source (a restarted service, a new writer).
  // A second: longer than any stall of a live service (an intruder must not
  // take the stream over while the FEM takes a slow step), shorter than a
  // service's restart.
  std::chrono::nanoseconds takeover{std::chrono::seconds(1)};
  // Refuses a sample that fails it (non-finite, out of range, wrong size).
  // Runs on the vendor thread.
  std::function<bool(const T&)> valid;
  // Where the refusals are counted; shared, so a status reporter can read
  // them after the subscriber is gone.
  std::shared_ptr<AdmissionCounts> counts = std::make_shared<AdmissionCounts>();
  // Of a keyed topic, the instance this reader follows (a body's ContactSets
  // or DeformationStates, each from its own writer): a sample it does not
  // want is passed over before anything else is judged, and not counted.
  // Empty: every instance. Samples of an instance no reader follows (an
  // intruder's) should be wanted by one of the readers, which then refuses
  // and counts them.
  std::function<bool(const T&)> wanted;
};

// The `wanted` filter of one of several readers of a topic keyed by body
// (ContactSet, DeformationState), one reader per body: reader `index` of
// `bodies` follows its body's instance. With `strays`, the first reader also
// takes the samples naming none of `bodies` (an intruder's), so that one
// reader judges, refuses and counts them rather than none.
template <class T>
std::function<bool(const T&)> body_instance(std::vector<std::uint32_t> bodies, std::size_t index,
                                            bool strays) {
  const std::uint32_t id = bodies.at(index);
  const bool take_strays = strays && index == 0;
  return [id, take_strays, bodies = std::move(bodies)](const T& sample) {
    const std::uint32_t key = sample.body_id();
    return key == id ||
           (take_strays && std::find(bodies.begin(), bodies.end(), key) == bodies.end());
  };
}

template <class T>
class Subscriber final : private detail::SampleSink {
 public:
  using Handler = std::function<void(const T&, const SampleInfo&)>;

  // `handler`, if given, sees every sample on the vendor thread; it must be
  // quick and must not call back into this subscriber.
  explicit Subscriber(Participant& participant,
                      QosProfile qos = QosProfile::for_role(TopicTraits<T>::kRole),
                      std::string_view topic_name = TopicTraits<T>::kName, Handler handler = {})
      : handler_(std::move(handler)) {
    detail::EndpointSpec spec{&detail::type_support<T>(), std::string(topic_name), qos};
    reader_ = participant.backend().create_reader(spec, this);
  }
  // A reader that lets in only what `admission` admits.
  Subscriber(Participant& participant, Admission<T> admission,
             QosProfile qos = QosProfile::for_role(TopicTraits<T>::kRole),
             std::string_view topic_name = TopicTraits<T>::kName)
      : admission_(std::move(admission)), gated_(true) {
    detail::EndpointSpec spec{&detail::type_support<T>(), std::string(topic_name), qos};
    reader_ = participant.backend().create_reader(spec, this);
  }
  ~Subscriber() override { reader_.reset(); }  // stop deliveries before members go
  Subscriber(const Subscriber&) = delete;
  Subscriber& operator=(const Subscriber&) = delete;

  // Consumer side (one thread): true if a newer sample arrived since the
  // last fetch; newest()/newest_info() then refer to it. Wait-free.
  bool fetch_newest() { return latest_.fetch(); }
  const T& newest() const { return latest_.value(); }
  const SampleInfo& newest_info() const { return latest_.info(); }

  // Blocks until a sample beyond `seen` samples has arrived or the timeout
  // passes; returns the number received so far. For start-up, lockstep and
  // event-driven loops (it locks): a 1 kHz tick polls fetch_newest() instead.
  std::uint64_t wait_for_samples(std::uint64_t seen, std::chrono::nanoseconds timeout) {
    std::unique_lock lock(wait_mutex_);
    waiters_.fetch_add(1, std::memory_order_seq_cst);
    wait_cv_.wait_for(lock, timeout, [&] { return latest_.published() > seen; });
    waiters_.fetch_sub(1, std::memory_order_relaxed);
    return latest_.published();
  }
  std::uint64_t received() const { return latest_.published(); }
  std::uint64_t missed() const { return missed_.load(std::memory_order_relaxed); }
  int matched_writers() const { return reader_->matched_writers(); }
  // What the Admission refused (all zero without one).
  const AdmissionCounts& admission_counts() const { return *admission_.counts; }

 private:
  // Called with gap_mutex_ held. True if the sample may go in.
  bool admit(const T& typed, const SampleInfo& info) {
    if (admission_.valid && !admission_.valid(typed)) {
      admission_.counts->invalid.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    const std::int64_t now_ns = monotonic_now_ns();
    if (!has_source_ || (info.source_key != source_key_ &&
                         now_ns - source_heard_ns_ > admission_.takeover.count())) {
      if (has_source_) admission_.counts->source_changes.fetch_add(1, std::memory_order_relaxed);
      has_source_ = true;
      source_key_ = info.source_key;
      source_seq_ = info.seq;
      source_heard_ns_ = now_ns;
      return true;
    }
    if (info.source_key != source_key_) {
      admission_.counts->foreign.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    if (info.seq <= source_seq_) {
      admission_.counts->out_of_order.fetch_add(1, std::memory_order_relaxed);
      return false;
    }
    source_seq_ = info.seq;
    source_heard_ns_ = now_ns;
    return true;
  }

  void deliver(const void* sample, std::int64_t source_time_ns, std::uint64_t source_key) override {
    const T& typed = *static_cast<const T*>(sample);
    const auto& header = typed.header();
    SampleInfo info;
    info.seq = header.seq();
    info.writer_id = header.writer_id();
    info.source_time_ns = source_time_ns;
    info.receive_time_ns = wall_now_ns();
    info.source_key = source_key;
    if (gated_ && admission_.wanted && !admission_.wanted(typed)) return;
    {
      // Sequence gaps per writer: tracks the most recent writer only, which
      // is exact for the single-writer topics fahr has.
      std::lock_guard lock(gap_mutex_);
      if (gated_ && !admit(typed, info)) return;
      // A reader of one instance sees a share of the writer's numbers: its
      // gaps are the other instances' samples, not losses.
      if (!admission_.wanted && info.writer_id == last_writer_ && info.seq > last_seq_ + 1) {
        info.missed_before = info.seq - last_seq_ - 1;
        missed_.fetch_add(info.missed_before, std::memory_order_relaxed);
      }
      last_writer_ = info.writer_id;
      last_seq_ = info.seq;
    }
    if (handler_) handler_(typed, info);
    latest_.publish(typed, info);
    // Wake waiters only if there are any: most readers poll, and the lock
    // and notify would otherwise cost every delivery.
    if (waiters_.load(std::memory_order_seq_cst) > 0) {
      { std::lock_guard lock(wait_mutex_); }
      wait_cv_.notify_all();
    }
  }

  Handler handler_;
  Admission<T> admission_;
  bool gated_ = false;
  bool has_source_ = false;
  std::uint64_t source_key_ = 0;
  std::uint64_t source_seq_ = 0;
  std::int64_t source_heard_ns_ = 0;
  LatestSample<T> latest_;
  std::mutex gap_mutex_;
  std::uint32_t last_writer_ = 0;
  std::uint64_t last_seq_ = 0;
  std::atomic<std::uint64_t> missed_{0};
  std::mutex wait_mutex_;
  std::condition_variable wait_cv_;
  std::atomic<int> waiters_{0};
  std::unique_ptr<detail::ReaderBackend> reader_;
};

}  // namespace fahr::common
