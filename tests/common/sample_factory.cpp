// Seeded sample contents for interop tests.
#include "sample_factory.h"

#include <algorithm>
#include <random>

#include "contact_setPubSubTypes.h"
#include "deformation_statePubSubTypes.h"
#include "device_posePubSubTypes.h"
#include "fahr/common/backend.h"
#include "force_commandPubSubTypes.h"
#include "glottic_viewPubSubTypes.h"
#include "scene_descriptionPubSubTypes.h"
#include "service_statusPubSubTypes.h"
#include "sim_clockPubSubTypes.h"

namespace fahr::test {
namespace {

class Values {
 public:
  explicit Values(std::uint64_t seed) : rng_(seed) {}
  double real() { return std::uniform_real_distribution<double>(-1e3, 1e3)(rng_); }
  float real32() { return static_cast<float>(real()); }
  std::uint32_t u32() { return static_cast<std::uint32_t>(rng_()); }
  std::uint64_t u64() { return rng_(); }
  std::int64_t i64() { return static_cast<std::int64_t>(rng_() >> 1); }
  std::int32_t i32() { return static_cast<std::int32_t>(u32() >> 1); }
  bool flag() { return (rng_() & 1U) != 0; }
  template <class E>
  E pick(int count) {
    return static_cast<E>(rng_() % static_cast<std::uint64_t>(count));
  }
  std::string text(std::size_t n) {
    std::string s(n, 'a');
    for (auto& c : s) c = static_cast<char>('a' + rng_() % 26);
    return s;
  }
  msg::Vec3 vec3() {
    msg::Vec3 v;
    v.x(real());
    v.y(real());
    v.z(real());
    return v;
  }
  msg::Pose pose() {
    msg::Pose p;
    p.position_m(vec3());
    msg::Quat q;
    q.w(real());
    q.x(real());
    q.y(real());
    q.z(real());
    p.orientation(q);
    return p;
  }
  msg::Mat3 mat3() {
    msg::Mat3 m;
    for (auto& x : m.m()) x = real();
    return m;
  }
  msg::SampleHeader header() {
    msg::SampleHeader h;
    h.seq(u64());
    h.source_time_ns(i64());
    h.sim_time_ns(i64());
    h.sim_step(u64());
    h.writer_id(u32());
    return h;
  }
  template <class V>
  void floats(V& v, std::size_t n) {
    v.resize(n);
    for (auto& x : v) x = real32();
  }
  template <class V>
  void u32s(V& v, std::size_t n) {
    v.resize(n);
    for (auto& x : v) x = u32();
  }

 private:
  std::mt19937_64 rng_;
};

msg::DurationStats stats(Values& v) {
  msg::DurationStats s;
  s.count(v.u64());
  s.mean_ns(v.i64());
  s.p50_ns(v.i64());
  s.p99_ns(v.i64());
  s.p999_ns(v.i64());
  s.max_ns(v.i64());
  return s;
}

}  // namespace

void fill(msg::DevicePose& s, std::uint64_t seed, std::size_t) {
  Values v(seed);
  s.header(v.header());
  s.device_id(v.u32());
  s.servo_tick(v.u64());
  s.device_time_ns(v.i64());
  s.world_from_stylus(v.pose());
  s.linear_velocity_mps(v.vec3());
  s.angular_velocity_radps(v.vec3());
  s.buttons(v.u32());
  s.renderable_force_n(v.real());
  s.max_stiffness_npm(v.real());
  s.rendered_force_n(v.vec3());
  s.safety_state(v.pick<msg::DeviceSafetyState>(5));
}

void fill(msg::ForceCommand& s, std::uint64_t seed, std::size_t) {
  Values v(seed);
  s.header(v.header());
  s.device_id(v.u32());
  s.answered_pose_seq(v.u64());
  s.answered_position_m(v.vec3());
  s.force_n(v.vec3());
  s.stiffness_npm(v.mat3());
  s.torque_nm(v.vec3());
  s.world_from_proxy(v.pose());
  s.lost_track(v.flag());
  s.device_minus_proxy_m(v.vec3());
  s.tissue_reaction_n(v.real());
  s.active_contacts(v.u32());
  s.fem_step(v.u64());
}

void fill(msg::ContactSet& s, std::uint64_t seed, std::size_t n) {
  Values v(seed);
  s.header(v.header());
  s.body_id(v.u32());
  s.haptic_tick(v.u64());
  s.fem_step(v.u64());
  s.layout_fingerprint(v.u64());
  s.tool_frozen(v.flag());
  s.contacts().resize(std::min<std::size_t>(n, msg::MAX_CONTACTS));
  for (auto& c : s.contacts()) {
    c.sphere_id(v.u32());
    c.other_body_id(v.u32());
    c.kind(v.pick<msg::ContactKind>(2));
    c.state(v.pick<msg::ConstraintState>(3));
    c.point_m(v.vec3());
    c.normal(v.vec3());
    c.hold_centre_m(v.vec3());
    c.penetration_m(v.real());
    c.force_n(v.real());
  }
}

void fill(msg::DeformationState& s, std::uint64_t seed, std::size_t n) {
  Values v(seed);
  s.header(v.header());
  s.body_id(v.u32());
  s.step(v.u64());
  s.step_s(v.real());
  s.asleep(v.flag());
  s.applied_contact_seq(v.u64());
  s.stale_contact_sets(v.u32());
  v.floats(s.positions_m(), std::min<std::size_t>(3 * n, msg::MAX_COORDS));
  v.floats(s.velocities_mps(), std::min<std::size_t>(3 * n, msg::MAX_COORDS));
  const std::size_t spheres = std::min<std::size_t>(n, msg::MAX_COMPLIANCE_SPHERES);
  v.u32s(s.compliance_sphere_ids(), spheres);
  v.floats(s.compliance_mpn(), (3 * spheres) * (3 * spheres + 1) / 2);  // the upper triangle
  v.floats(s.compliance_free_centres_m(), 3 * spheres);
}

void fill(msg::SceneDescription& s, std::uint64_t seed, std::size_t n) {
  Values v(seed);
  s.header(v.header());
  s.body_id(v.u32());
  s.body_count(v.u32());
  s.scene_name(v.text(20));
  s.body_name(v.text(12));
  s.role(v.pick<msg::BodyRole>(3));
  s.mesh_uri(v.text(40));
  s.layout_fingerprint(v.u64());
  const std::string text = v.text(std::min<std::size_t>(n * 8, msg::MAX_SCENE_TEXT));
  s.scene_text_utf8().assign(text.begin(), text.end());
  v.floats(s.rest_positions_m(), 3 * n);
  v.u32s(s.tets(), 4 * n);
  v.u32s(s.triangles(), 3 * n);
  v.floats(s.sphere_rest_m(), 4 * n);
  v.u32s(s.sphere_link_offsets(), n + 1);
  v.u32s(s.sphere_nodes(), 4 * n);
  v.floats(s.sphere_weights(), 4 * n);
}

void fill(msg::ServiceStatus& s, std::uint64_t seed, std::size_t n) {
  Values v(seed);
  s.header(v.header());
  s.service_id(v.u32());
  s.service_name(v.text(10));
  s.host(v.text(16));
  s.pid(v.u32());
  s.dds_vendor(v.text(8));
  s.state(v.pick<msg::ServiceState>(4));
  s.nominal_rate_hz(v.real());
  s.measured_rate_hz(v.real());
  s.ticks(v.u64());
  s.period(stats(v));
  s.tick_cpu(stats(v));
  s.late_periods(v.u64());
  s.metrics().resize(std::min<std::size_t>(n, 32));
  for (auto& m : s.metrics()) {
    m.name(v.text(20));
    m.value(v.real());
  }
}

void fill(msg::ServiceEvents& s, std::uint64_t seed, std::size_t n) {
  Values v(seed);
  s.header(v.header());
  s.service_id(v.u32());
  s.service_name(v.text(10));
  s.dropped_events(v.u32());
  s.dropped_spans(v.u32());
  s.qos_events().resize(std::min<std::size_t>(n, 128));
  for (auto& e : s.qos_events()) {
    e.time_ns(v.i64());
    e.kind(v.pick<msg::QosEventKind>(10));
    e.topic(v.text(30));
    e.total_count(v.i32());
    e.total_count_change(v.i32());
    e.current_count(v.i32());
    e.not_alive_count(v.i32());
  }
  s.tick_spans().resize(std::min<std::size_t>(n, 1024));
  for (auto& t : s.tick_spans()) {
    t.tick(v.u64());
    t.start_ns(v.i64());
    t.duration_ns(v.i64());
    t.cpu_ns(v.i64());
  }
  s.errors().resize(std::min<std::size_t>(n, 8));
  for (auto& e : s.errors()) {
    e.time_ns(v.i64());
    e.text(v.text(120));
  }
}

void fill(msg::SimClock& s, std::uint64_t seed, std::size_t) {
  Values v(seed);
  s.header(v.header());
  s.granted_step(v.u64());
  s.base_period_ns(v.i64());
  s.sim_time_ns(v.i64());
  s.stop(v.flag());
}

void fill(msg::StepAck& s, std::uint64_t seed, std::size_t) {
  Values v(seed);
  s.header(v.header());
  s.participant_id(v.u32());
  s.participant_name(v.text(12));
  s.completed_step(v.i64());
  s.output_hash(v.u64());
}

void fill(msg::GlotticView& s, std::uint64_t seed, std::size_t) {
  Values v(seed);
  s.header(v.header());
  s.tool_body_id(v.u32());
  s.fem_step(v.u64());
  s.haptic_tick(v.u64());
  s.visible_percent(v.real());
  s.samples_facing(v.u32());
  s.samples_seen(v.u32());
  s.eye_m(v.vec3());
  s.opening_centre_m(v.vec3());
  s.tool_force_n(v.real());
  s.peak_tool_force_n(v.real());
}

template <class T>
std::vector<std::uint8_t> cdr_bytes(const T& sample) {
  auto* type = static_cast<eprosima::fastdds::dds::TopicDataType*>(
      common::detail::type_support<T>().make_fast_type());
  T copy = sample;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type->getSerializedSizeProvider(&copy)());
  type->serialize(&copy, &payload);
  std::vector<std::uint8_t> bytes(payload.data, payload.data + payload.length);
  delete type;
  return bytes;
}

template std::vector<std::uint8_t> cdr_bytes(const msg::DevicePose&);
template std::vector<std::uint8_t> cdr_bytes(const msg::ForceCommand&);
template std::vector<std::uint8_t> cdr_bytes(const msg::ContactSet&);
template std::vector<std::uint8_t> cdr_bytes(const msg::DeformationState&);
template std::vector<std::uint8_t> cdr_bytes(const msg::SceneDescription&);
template std::vector<std::uint8_t> cdr_bytes(const msg::ServiceStatus&);
template std::vector<std::uint8_t> cdr_bytes(const msg::ServiceEvents&);
template std::vector<std::uint8_t> cdr_bytes(const msg::SimClock&);
template std::vector<std::uint8_t> cdr_bytes(const msg::StepAck&);
template std::vector<std::uint8_t> cdr_bytes(const msg::GlotticView&);

}  // namespace fahr::test
