// DDS subscriptions, the replay thread, the remote-input publisher.
#include "fahr/visualizer_service/sources.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <optional>

#include "device_posePubSubTypes.h"
#include "fahr/common/cdr_bytes.h"
#include "fahr/common/clock.h"
#include "fahr/common/publisher.h"
#include "fahr/common/topics.h"

namespace fahr::visualizer_service {
namespace {

using namespace std::chrono_literals;

// A viewer's reader: what the writers offer, keeping only the newest sample
// per instance, judging nothing (no deadline, liveliness or lifespan), so a
// viewer never changes what a writer must do. Best effort for the streams:
// a reliable writer (lockstep runs) never waits for the viewer.
common::QosProfile viewer_qos(common::TopicRole role) {
  common::QosProfile q = common::QosProfile::for_role(role);
  q.deadline = {};
  q.liveliness_lease = {};
  q.lifespan = {};
  if (role == common::TopicRole::kServoStream || role == common::TopicRole::kStateStream) {
    q.reliability = common::Reliability::kBestEffort;
    q.durability = common::Durability::kVolatile;
    q.history_depth = 1;
  }
  return q;
}

template <class T>
std::unique_ptr<common::RawSubscriber> subscribe(common::Participant& p, LiveState& live,
                                                 std::size_t topic) {
  return common::RawSubscriber::create<T>(
      p, viewer_qos(common::TopicTraits<T>::kRole),
      [&live, topic](std::span<const std::uint8_t> cdr, std::int64_t) {
        live.put(topic, cdr, common::wall_now_ns());
      });
}

constexpr std::uint64_t kStepNs = 10'000'000;          // the replay thread's step, wall time
constexpr std::uint64_t kSeekHistoryNs = 500'000'000;  // recorded time refilled before a seek

}  // namespace

DdsSource::DdsSource(common::Participant& participant, LiveState& live) {
  subscribers_.push_back(subscribe<msg::DevicePose>(participant, live, kDevicePose));
  subscribers_.push_back(subscribe<msg::ForceCommand>(participant, live, kForceCommand));
  subscribers_.push_back(subscribe<msg::ContactSet>(participant, live, kContactSet));
  subscribers_.push_back(subscribe<msg::DeformationState>(participant, live, kDeformationState));
  subscribers_.push_back(subscribe<msg::SceneDescription>(participant, live, kSceneDescription));
  subscribers_.push_back(subscribe<msg::ServiceStatus>(participant, live, kServiceStatus));
}

DdsSource::~DdsSource() {
  subscribers_.clear();
}

int DdsSource::matched_writers() const {
  int n = 0;
  for (const auto& s : subscribers_) n += s->matched_writers();
  return n;
}

ReplaySource::ReplaySource(const std::string& path, LiveState& live, double speed)
    : reader_(path), live_(live), speed_(std::clamp(speed, 0.05, 4.0)) {
  if (!reader_.ok()) throw std::runtime_error(reader_.error());
  cursor_ = reader_.start_time();
  // The scene is latched: recorded once, near the start. Read it now so a
  // seek anywhere still has the meshes.
  reader_.read(reader_.start_time(), reader_.start_time() + 5'000'000'000ULL,
               [&](const mcap::Channel& c, const mcap::MessageView& m) {
                 if (topic_index(c.topic) == kSceneDescription)
                   live_.put(kSceneDescription, m.data, static_cast<std::int64_t>(m.log_time));
               });
}

ReplaySource::~ReplaySource() {
  stop();
}

void ReplaySource::start() {
  thread_ = std::thread([this] { run(); });
}

void ReplaySource::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

double ReplaySource::duration_s() const {
  return static_cast<double>(reader_.end_time() - reader_.start_time()) * 1e-9;
}

std::string ReplaySource::control(const std::string& action, double value) {
  std::lock_guard lock(mutex_);
  if (action == "pause") {
    paused_ = true;
  } else if (action == "play") {
    paused_ = false;
  } else if (action == "speed") {
    if (!(value >= 0.05 && value <= 4.0)) return "speed must be 0.05-4";
    speed_ = value;
  } else if (action == "seek") {
    if (!(value >= 0.0 && value <= duration_s())) return "seek must be within the recording";
    seek_to_ = reader_.start_time() + static_cast<std::uint64_t>(value * 1e9);
    seek_pending_ = true;
  } else {
    return "unknown replay action";
  }
  return {};
}

std::string ReplaySource::position_json() const {
  std::lock_guard lock(mutex_);
  char text[200];
  std::snprintf(text, sizeof(text),
                "{\"op\":\"replay\",\"t\":%.3f,\"duration\":%.3f,\"paused\":%s,\"speed\":%.3g,"
                "\"finished\":%s}",
                static_cast<double>(cursor_ - reader_.start_time()) * 1e-9, duration_s(),
                paused_ ? "true" : "false", speed_, finished_ ? "true" : "false");
  return text;
}

namespace {

// The recorded streams a replay hands the page. The glottic view is
// recomputed from the recorded geometry (the replay's GlotticViewService),
// so a recording without it shows it too; the scene is read once.
bool replayed(std::size_t topic) {
  return topic != kTopicCount && topic != kSceneDescription && topic != kGlotticView;
}

}  // namespace

void ReplaySource::fill(std::uint64_t begin, std::uint64_t end) {
  reader_.read(begin, end, [&](const mcap::Channel& c, const mcap::MessageView& m) {
    const std::size_t topic = topic_index(c.topic);
    if (replayed(topic)) live_.put(topic, m.data, static_cast<std::int64_t>(m.log_time));
  });
  chunks_read_ = reader_.chunks_read();
}

void ReplaySource::refill(std::uint64_t cursor) {
  // The state as it stood at the cursor: each stream's newest sample
  // however old (a stream the recorder received nothing of for a while,
  // a lockstep run stalled under a slow FEM step, still shows its last
  // sample), then the last half second in order.
  const std::uint64_t begin = cursor > reader_.start_time() + kSeekHistoryNs
                                  ? cursor - kSeekHistoryNs
                                  : reader_.start_time();
  reader_.read_newest(
      begin, [](const mcap::Channel& c) { return replayed(topic_index(c.topic)); },
      [&](const mcap::Channel& c, const mcap::MessageView& m) {
        live_.put(topic_index(c.topic), m.data, static_cast<std::int64_t>(m.log_time));
      });
  fill(begin, cursor + 1);
}

void ReplaySource::run() {
  auto next = std::chrono::steady_clock::now();
  while (!stop_) {
    next += std::chrono::nanoseconds(kStepNs);
    std::this_thread::sleep_until(next);
    std::uint64_t begin = 0, end = 0;
    std::optional<std::uint64_t> seeked;
    {
      std::lock_guard lock(mutex_);
      if (seek_pending_) {
        seek_pending_ = false;
        cursor_ = seek_to_;
        finished_ = false;
        seeked = cursor_;
      } else if (!paused_ && !finished_) {
        begin = cursor_ + 1;
        end = std::min(
            reader_.end_time() + 1,
            cursor_ + 1 + static_cast<std::uint64_t>(static_cast<double>(kStepNs) * speed_));
        cursor_ = end - 1;
        if (cursor_ >= reader_.end_time()) finished_ = true;
      }
    }
    if (seeked) {
      const LiveState::Batch batch(live_);
      live_.clear_streams();
      refill(*seeked);
    } else if (end > begin) {
      fill(begin, end);
    }
  }
}

struct RemoteInput::Impl {
  explicit Impl(common::Participant& p)
      : publisher(p, common::QosProfile::for_role(common::TopicRole::kServoStream),
                  "fahr/RemoteInput") {}
  std::mutex mutex;
  common::Publisher<msg::DevicePose> publisher;
  msg::DevicePose sample;
};

RemoteInput::RemoteInput(common::Participant& participant)
    : impl_(std::make_unique<Impl>(participant)) {}
RemoteInput::~RemoteInput() = default;

void RemoteInput::publish(const RemotePose& pose) {
  std::lock_guard lock(impl_->mutex);
  msg::DevicePose& s = impl_->sample;
  s.device_id(0);
  s.device_time_ns(common::monotonic_now_ns());
  s.world_from_stylus().position_m().x(pose.p[0]);
  s.world_from_stylus().position_m().y(pose.p[1]);
  s.world_from_stylus().position_m().z(pose.p[2]);
  s.world_from_stylus().orientation().w(pose.q[0]);
  s.world_from_stylus().orientation().x(pose.q[1]);
  s.world_from_stylus().orientation().y(pose.q[2]);
  s.world_from_stylus().orientation().z(pose.q[3]);
  s.buttons(pose.buttons);
  impl_->publisher.write(s);
}

bool RemoteInput::publish_cdr(std::span<const std::uint8_t> cdr) {
  std::lock_guard lock(impl_->mutex);
  msg::DevicePose s;
  if (!common::decode_cdr<msg::DevicePosePubSubType>(cdr, s)) return false;
  impl_->publisher.write(s);
  return true;
}

}  // namespace fahr::visualizer_service
