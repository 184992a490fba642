// Lockstep coordinator, client and the read rule.
#include "fahr/common/lockstep.h"

#include <algorithm>
#include <cstring>
#include <memory>
#include <thread>

#include "contact_setPubSubTypes.h"
#include "deformation_statePubSubTypes.h"
#include "device_posePubSubTypes.h"
#include "force_commandPubSubTypes.h"
#include "scene_descriptionPubSubTypes.h"
#include "service_statusPubSubTypes.h"
#include "sim_clockPubSubTypes.h"

namespace fahr::common {

std::optional<std::uint64_t> producer_step_for(std::uint64_t consumer_step,
                                               std::uint64_t producer_period) {
  if (consumer_step == 0 || producer_period == 0) return std::nullopt;
  return (consumer_step - 1) / producer_period * producer_period;
}

void OutputHash::add_bytes(const void* data, std::size_t size) {
  const auto* bytes = static_cast<const std::uint8_t*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    value_ ^= bytes[i];
    value_ *= 1099511628211ULL;
  }
}

template <class T>
void OutputHash::add(const T& sample) {
  using eprosima::fastdds::dds::TopicDataType;
  static const std::unique_ptr<TopicDataType> type(
      static_cast<TopicDataType*>(detail::type_support<T>().make_fast_type()));
  void* data = const_cast<T*>(&sample);
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type->getSerializedSizeProvider(data)());
  type->serialize(data, &payload);
  // CDR layout of the leading SampleHeader after the 4-byte encapsulation:
  // seq at 0, source_time_ns at 8, sim_time_ns at 16, sim_step at 24,
  // writer_id at 32. Zero the writer stamp; keep the simulated time.
  constexpr std::size_t kEncapsulation = 4;
  std::memset(payload.data + kEncapsulation, 0, 16);
  std::memset(payload.data + kEncapsulation + 32, 0, 4);
  add_bytes(payload.data, payload.length);
}

template void OutputHash::add(const msg::DevicePose&);
template void OutputHash::add(const msg::ForceCommand&);
template void OutputHash::add(const msg::ContactSet&);
template void OutputHash::add(const msg::DeformationState&);
template void OutputHash::add(const msg::SceneDescription&);
template void OutputHash::add(const msg::ServiceStatus&);
template void OutputHash::add(const msg::ServiceEvents&);

namespace {
QosProfile ack_qos() {
  QosProfile qos = QosProfile::for_role(TopicRole::kLockstep);
  qos.history_depth = 64;
  return qos;
}
}  // namespace

LockstepCoordinator::LockstepCoordinator(Participant& participant,
                                         std::chrono::nanoseconds base_period)
    : base_period_(base_period),
      clock_(participant),
      acks_(participant, ack_qos(), TopicTraits<msg::StepAck>::kName,
            [this](const msg::StepAck& ack, const SampleInfo&) { on_ack(ack); }) {}

void LockstepCoordinator::on_ack(const msg::StepAck& ack) {
  {
    std::lock_guard lock(mutex_);
    const std::string name = ack.participant_name().to_string();
    auto [it, inserted] = completed_.try_emplace(name, ack.completed_step());
    if (!inserted && ack.completed_step() > it->second) it->second = ack.completed_step();
    if (inserted || ack.completed_step() >= it->second) hashes_[name] = ack.output_hash();
  }
  changed_.notify_all();
}

void LockstepCoordinator::grant(std::uint64_t step, bool stop) {
  msg::SimClock clock;
  clock.granted_step(step);
  clock.base_period_ns(base_period_.count());
  clock.sim_time_ns(static_cast<std::int64_t>(step + 1) * base_period_.count());
  clock.stop(stop);
  clock.header().sim_step(step);
  clock.header().sim_time_ns(clock.sim_time_ns());
  clock_.write(clock);
}

LockstepCoordinator::Result LockstepCoordinator::run(const std::vector<std::string>& participants,
                                                     std::uint64_t total_steps,
                                                     std::chrono::milliseconds stall_timeout,
                                                     double pace) {
  Result result;
  auto all_through = [&](std::int64_t step) {
    return std::all_of(participants.begin(), participants.end(), [&](const std::string& name) {
      auto it = completed_.find(name);
      return it != completed_.end() && it->second >= step;
    });
  };
  std::unique_lock lock(mutex_);
  if (!changed_.wait_for(lock, stall_timeout, [&] { return all_through(-1); })) return result;
  const auto paced_start = std::chrono::steady_clock::now();
  for (std::uint64_t step = 0; step < total_steps; ++step) {
    lock.unlock();
    if (pace > 0.0) {
      // Step k's simulated start, k base periods, in wall time at this pace.
      const auto due = std::chrono::duration<double, std::nano>(
          static_cast<double>(step) * static_cast<double>(base_period_.count()) / pace);
      std::this_thread::sleep_until(
          paced_start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(due));
    }
    grant(step, false);
    lock.lock();
    if (!changed_.wait_for(lock, stall_timeout,
                           [&] { return all_through(static_cast<std::int64_t>(step)); })) {
      result.steps = step;
      return result;
    }
  }
  result.completed = true;
  result.steps = total_steps;
  result.hashes = hashes_;
  lock.unlock();
  grant(total_steps == 0 ? 0 : total_steps - 1, true);
  return result;
}

LockstepClient::LockstepClient(Participant& participant, std::string name)
    : name_(std::move(name)),
      id_(participant.writer_id()),
      acks_(participant, ack_qos()),
      clock_(participant, QosProfile::for_role(TopicRole::kLockstep),
             TopicTraits<msg::SimClock>::kName,
             [this](const msg::SimClock& clock, const SampleInfo&) { on_clock(clock); }) {}

void LockstepClient::on_clock(const msg::SimClock& clock) {
  {
    std::lock_guard lock(mutex_);
    granted_ = std::max(granted_, static_cast<std::int64_t>(clock.granted_step()));
    stop_ = stop_ || clock.stop();
  }
  changed_.notify_all();
}

void LockstepClient::join() {
  complete_through(static_cast<std::uint64_t>(-1), 0);
}

bool LockstepClient::wait_for_grant(std::uint64_t step, std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  const auto wanted = static_cast<std::int64_t>(step);
  changed_.wait_for(lock, timeout, [&] { return granted_ >= wanted || stop_; });
  return granted_ >= wanted && !(stop_ && granted_ < wanted);
}

void LockstepClient::complete_through(std::uint64_t step, std::uint64_t output_hash) {
  msg::StepAck ack;
  ack.participant_id(id_);
  ack.participant_name(name_);
  ack.completed_step(static_cast<std::int64_t>(step));
  ack.output_hash(output_hash);
  ack.header().sim_step(step);
  acks_.write(ack);
}

bool LockstepClient::wait_for_stop(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, timeout, [&] { return stop_; });
}

bool LockstepClient::stopped() const {
  std::lock_guard lock(mutex_);
  return stop_;
}

}  // namespace fahr::common
