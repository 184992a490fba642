// Ping and echo through Cyclone DDS's own C API and idlc's C types, with
// the same QoS the transport uses, for the transport/raw ratio.
#include <dds/dds.h>

#include <cstdlib>
#include <stdexcept>
#include <vector>

#include "cyclone/deformation_state.h"
#include "cyclone/device_pose.h"
#include "echo_waiter.h"
#include "ping_path.h"

namespace fahr::bench {
namespace {

std::uint64_t id_of(const fahr_msg_DevicePose& s) {
  return s.servo_tick;
}
std::uint64_t id_of(const fahr_msg_DeformationState& s) {
  return s.step;
}
void set_id(fahr_msg_DevicePose& s, std::uint64_t id) {
  s.servo_tick = id;
}
void set_id(fahr_msg_DeformationState& s, std::uint64_t id) {
  s.step = id;
}

template <class T>
const dds_topic_descriptor_t& descriptor();
template <>
const dds_topic_descriptor_t& descriptor<fahr_msg_DevicePose>() {
  return fahr_msg_DevicePose_desc;
}
template <>
const dds_topic_descriptor_t& descriptor<fahr_msg_DeformationState>() {
  return fahr_msg_DeformationState_desc;
}

// One participant, one writer, one reader whose listener takes each sample
// (on loan, no copy) and calls the derived class.
template <class T>
class RawCycloneEndpoint {
 public:
  RawCycloneEndpoint(std::uint32_t domain, const char* out_topic, const char* in_topic) {
    participant_ = dds_create_participant(domain, nullptr, nullptr);
    if (participant_ < 0) throw std::runtime_error("raw Cyclone DDS: no participant");
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
    const dds_entity_t out =
        dds_create_topic(participant_, &descriptor<T>(), out_topic, nullptr, nullptr);
    const dds_entity_t in =
        dds_create_topic(participant_, &descriptor<T>(), in_topic, nullptr, nullptr);
    writer_ = dds_create_writer(participant_, out, qos, nullptr);
    in_topic_ = in;
    qos_ = qos;
  }
  virtual ~RawCycloneEndpoint() {
    dds_delete_qos(qos_);
    dds_delete(participant_);
  }
  void write(const T& sample) { dds_write(writer_, &sample); }

 protected:
  virtual void on_sample(const T& sample) = 0;
  // The derived class starts and stops reading, so the listener never
  // calls on_sample() of a half-built or half-destroyed object.
  void start_reading() {
    dds_listener_t* listener = dds_create_listener(this);
    dds_lset_data_available(listener, &RawCycloneEndpoint::on_data);
    reader_ = dds_create_reader(participant_, in_topic_, qos_, listener);
    dds_delete_listener(listener);
  }
  void stop_reading() { dds_delete(reader_); }

 private:
  static void on_data(dds_entity_t reader, void* arg) {
    auto* self = static_cast<RawCycloneEndpoint*>(arg);
    void* samples[1] = {nullptr};
    dds_sample_info_t info;
    while (dds_take(reader, samples, &info, 1, 1) == 1) {
      if (info.valid_data) self->on_sample(*static_cast<const T*>(samples[0]));
      dds_return_loan(reader, samples, 1);
      samples[0] = nullptr;
    }
  }

  dds_entity_t participant_ = 0;
  dds_entity_t writer_ = 0;
  dds_entity_t reader_ = 0;
  dds_entity_t in_topic_ = 0;
  dds_qos_t* qos_ = nullptr;
};

template <class T>
class RawCyclonePing final : public PingPath, private RawCycloneEndpoint<T> {
 public:
  RawCyclonePing(std::uint32_t domain, const Payload& payload)
      : RawCycloneEndpoint<T>(domain, kRawPing, kRawPong) {
    if constexpr (std::is_same_v<T, fahr_msg_DeformationState>) {
      positions_.assign(payload.payload_bytes / 8, 0.5F);
      velocities_.assign(payload.payload_bytes / 8, -0.5F);
      sample_.positions_m = {static_cast<std::uint32_t>(positions_.size()),
                             static_cast<std::uint32_t>(positions_.size()), positions_.data(),
                             false};
      sample_.velocities_mps = {static_cast<std::uint32_t>(velocities_.size()),
                                static_cast<std::uint32_t>(velocities_.size()), velocities_.data(),
                                false};
    }
    this->start_reading();
  }
  ~RawCyclonePing() override { this->stop_reading(); }
  void ping(std::uint64_t id) override {
    set_id(sample_, id);
    this->write(sample_);
  }
  bool wait_echo(std::uint64_t id, std::chrono::milliseconds timeout) override {
    return waiter_.wait(id, timeout);
  }

 private:
  void on_sample(const T& sample) override { waiter_.arrived(id_of(sample)); }
  EchoWaiter waiter_;
  T sample_{};
  std::vector<float> positions_;
  std::vector<float> velocities_;
};

template <class T>
class RawCycloneEcho final : public EchoPath, private RawCycloneEndpoint<T> {
 public:
  explicit RawCycloneEcho(std::uint32_t domain)
      : RawCycloneEndpoint<T>(domain, kRawPong, kRawPing) {
    this->start_reading();
  }
  ~RawCycloneEcho() override { this->stop_reading(); }

 private:
  void on_sample(const T& sample) override { this->write(sample); }
};

}  // namespace

std::unique_ptr<PingPath> make_raw_cyclone_ping(std::uint32_t domain, const Payload& payload) {
  if (payload.small) return std::make_unique<RawCyclonePing<fahr_msg_DevicePose>>(domain, payload);
  return std::make_unique<RawCyclonePing<fahr_msg_DeformationState>>(domain, payload);
}

std::unique_ptr<EchoPath> make_raw_cyclone_echo(std::uint32_t domain, const Payload& payload) {
  if (payload.small) return std::make_unique<RawCycloneEcho<fahr_msg_DevicePose>>(domain);
  return std::make_unique<RawCycloneEcho<fahr_msg_DeformationState>>(domain);
}

}  // namespace fahr::bench
