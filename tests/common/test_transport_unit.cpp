// Transport unit tests on the in-process bus (and vendor configuration
// errors): the API behaves the same whichever vendor carries it.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include "fahr/common/background_publisher.h"
#include "fahr/common/clock.h"
#include "fahr/common/config_error.h"
#include "fahr/common/publisher.h"
#include "fahr/common/subscriber.h"
#include "sample_factory.h"

namespace fahr::test {
namespace {

using common::ConfigError;
using common::Participant;
using common::TransportConfig;
using common::Vendor;

TransportConfig in_process(std::uint32_t domain) {
  TransportConfig config;
  config.vendor = Vendor::kInProcess;
  config.domain_id = domain;
  return config;
}

template <class T>
void expect_in_process_round_trip(std::size_t n) {
  Participant a(in_process(1));
  Participant b(in_process(1));
  common::Subscriber<T> sub(b);
  common::Publisher<T> pub(a);
  T sent;
  fill(sent, 7, n);
  ASSERT_TRUE(pub.write(sent));
  ASSERT_TRUE(sub.fetch_newest());
  EXPECT_EQ(cdr_bytes(sub.newest()), cdr_bytes(sent));
  EXPECT_EQ(sub.newest_info().seq, 1U);
  EXPECT_EQ(sub.newest_info().writer_id, a.writer_id());
}

TEST(InProcess, EveryTypeRoundTrips) {
  expect_in_process_round_trip<msg::DevicePose>(0);
  expect_in_process_round_trip<msg::ForceCommand>(0);
  expect_in_process_round_trip<msg::ContactSet>(64);
  expect_in_process_round_trip<msg::DeformationState>(1000);
  expect_in_process_round_trip<msg::SceneDescription>(100);
  expect_in_process_round_trip<msg::ServiceStatus>(8);
  expect_in_process_round_trip<msg::ServiceEvents>(8);
  expect_in_process_round_trip<msg::SimClock>(0);
  expect_in_process_round_trip<msg::StepAck>(0);
  expect_in_process_round_trip<msg::GlotticView>(0);
}

TEST(InProcess, NewestWinsAndSequenceGapsAreCounted) {
  Participant p(in_process(2));
  common::Subscriber<msg::DevicePose> sub(p);
  common::Publisher<msg::DevicePose> pub(p);
  msg::DevicePose pose;
  for (std::uint64_t i = 1; i <= 5; ++i) {
    pose.servo_tick(i);
    pub.write(pose);
  }
  ASSERT_TRUE(sub.fetch_newest());
  EXPECT_EQ(sub.newest().servo_tick(), 5U);
  EXPECT_EQ(sub.newest_info().seq, 5U);
  EXPECT_FALSE(sub.fetch_newest()) << "nothing newer arrived";
  EXPECT_EQ(sub.missed(), 0U);
  EXPECT_EQ(sub.received(), 5U);
}

TEST(InProcess, TransientLocalReachesLateReaders) {
  Participant p(in_process(3));
  common::Publisher<msg::SceneDescription> pub(p);
  msg::SceneDescription scene;
  scene.body_id(9);
  pub.write(scene);
  common::Subscriber<msg::SceneDescription> late(p);
  ASSERT_TRUE(late.fetch_newest());
  EXPECT_EQ(late.newest().body_id(), 9U);
}

TEST(InProcess, BestEffortWriterDoesNotServeReliableReader) {
  Participant p(in_process(4));
  common::QosProfile reliable = common::QosProfile::for_role(common::TopicRole::kStateStream);
  common::Subscriber<msg::DevicePose> sub(p, reliable);
  common::Publisher<msg::DevicePose> pub(p);  // servo stream: best effort
  EXPECT_EQ(pub.matched_readers(), 0);
  EXPECT_EQ(p.events().count(common::EventKind::kRequestedIncompatibleQos), 1);
  msg::DevicePose pose;
  pub.write(pose);
  EXPECT_FALSE(sub.fetch_newest());
}

TEST(InProcess, PartitionsSeparateStations) {
  TransportConfig a = in_process(5);
  a.partition = "station-a";
  TransportConfig b = in_process(5);
  b.partition = "station-b";
  Participant pa(a);
  Participant pb(b);
  common::Subscriber<msg::DevicePose> sub(pb);
  common::Publisher<msg::DevicePose> pub(pa);
  msg::DevicePose pose;
  pub.write(pose);
  EXPECT_FALSE(sub.fetch_newest());
}

TEST(Config, UnknownVendorListsTheValidOnes) {
  try {
    common::resolve_vendor("opensplice");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("opensplice"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("fastdds, cyclonedds, inprocess"), std::string::npos);
  }
  setenv("FAHR_DDS", "zenoh", 1);
  EXPECT_THROW(common::resolve_vendor(""), ConfigError);
  setenv("FAHR_DDS", "cyclonedds", 1);
  EXPECT_EQ(common::resolve_vendor(""), Vendor::kCyclone);
  EXPECT_EQ(common::resolve_vendor("fastdds"), Vendor::kFastDds) << "the flag wins";
  unsetenv("FAHR_DDS");
}

TEST(Config, DomainOutOfRangeIsRefused) {
  TransportConfig config = in_process(231);
  EXPECT_THROW(Participant p(config), ConfigError);
  EXPECT_THROW(common::transport_config_from("inprocess", "999", "", "x"), ConfigError);
  EXPECT_THROW(common::transport_config_from("inprocess", "seven", "", "x"), ConfigError);
}

TEST(Config, MissingAndMalformedProfilesAreRefused) {
  TransportConfig config;
  config.vendor = Vendor::kFastDds;
  config.profile_file = "/nonexistent/profile.xml";
  EXPECT_THROW(Participant p(config), ConfigError);

  const auto dir = std::filesystem::temp_directory_path() / "fahr_profiles";
  std::filesystem::create_directories(dir);
  const auto bad_fast = (dir / "bad_fast.xml").string();
  std::ofstream(bad_fast)
      << "<profiles><participant profile_name=\"x\"><rtps><unclosed></profiles>";
  config.profile_file = bad_fast;
  EXPECT_THROW(Participant p(config), ConfigError);

  const auto bad_cyclone = (dir / "bad_cyclone.xml").string();
  std::ofstream(bad_cyclone) << "<CycloneDDS><Domain><General><NoSuchSetting>1</NoSuchSetting></"
                                "General></Domain></CycloneDDS>";
  config.vendor = Vendor::kCyclone;
  config.domain_id = 17;
  config.profile_file = bad_cyclone;
  EXPECT_THROW(Participant p(config), ConfigError);

  config.profile_file = bad_fast;  // a Fast DDS file given to Cyclone
  EXPECT_THROW(Participant p(config), ConfigError);
}

}  // namespace
}  // namespace fahr::test

#include "fahr/common/service_reporter.h"

namespace fahr::test {
namespace {

TEST(ServiceReporter, ReportsTickStatisticsLatePeriodsAndQosEvents) {
  Participant p(in_process(6));
  common::Subscriber<msg::ServiceStatus> status(p);
  common::Subscriber<msg::ServiceEvents> events(p);
  common::TickRecorder recorder;
  common::ServiceReporter reporter(
      p, {"test_service", 1000.0, std::chrono::hours(1)}, recorder,
      [](auto& metrics) { metrics.emplace_back("latency_p99_ms", 1.25); });
  std::int64_t start = 1'000'000'000;
  for (std::uint64_t tick = 0; tick < 101; ++tick) {
    start += tick == 50 ? 3'000'000 : 1'000'000;  // one period of 3 ms: late
    recorder.push({tick, start, 200'000, 150'000});
  }
  reporter.report();
  ASSERT_TRUE(status.fetch_newest());
  const auto& s = status.newest();
  EXPECT_EQ(s.service_name().to_string(), "test_service");
  EXPECT_EQ(s.ticks(), 101U);
  EXPECT_EQ(s.late_periods(), 1U);
  EXPECT_EQ(s.period().count(), 100U);
  EXPECT_EQ(s.period().p50_ns(), 1'000'000);
  EXPECT_EQ(s.period().max_ns(), 3'000'000);
  EXPECT_EQ(s.tick_cpu().p50_ns(), 150'000);
  // Each of the participant's writers' sent counts first (a status counts
  // the reports before it), then the service's own figures.
  ASSERT_EQ(s.metrics().size(), 3U);
  EXPECT_EQ(s.metrics()[0].name().to_string(), "sent fahr/ServiceStatus");
  EXPECT_EQ(s.metrics()[0].value(), 0.0);
  EXPECT_EQ(s.metrics()[1].name().to_string(), "sent fahr/ServiceEvents");
  EXPECT_EQ(s.metrics()[2].name().to_string(), "latency_p99_ms");
  EXPECT_EQ(s.metrics()[2].value(), 1.25);
  ASSERT_TRUE(events.fetch_newest());
  EXPECT_EQ(events.newest().tick_spans().size(), 101U);
  bool saw_match = false;
  for (const auto& e : events.newest().qos_events())
    saw_match |= e.kind() == msg::QOS_PUBLICATION_MATCHED;
  EXPECT_TRUE(saw_match) << "the reporter's own publications matched the test's readers";
  reporter.report();
  ASSERT_TRUE(status.fetch_newest());
  EXPECT_EQ(status.newest().metrics()[0].value(), 1.0);
  EXPECT_EQ(status.newest().metrics()[1].value(), 1.0);
}

// A writer that stamps its own headers, as a hostile participant can.
class ForgingWriter {
 public:
  explicit ForgingWriter(Participant& participant) {
    common::detail::EndpointSpec spec{
        &common::detail::type_support<msg::DevicePose>(),
        std::string(common::TopicTraits<msg::DevicePose>::kName),
        common::QosProfile::for_role(common::TopicRole::kServoStream)};
    writer_ = participant.backend().create_writer(spec);
  }
  void write(std::uint64_t seq, double x) {
    msg::DevicePose pose;
    pose.header().seq(seq);
    pose.header().writer_id(7);
    pose.world_from_stylus().position_m().x() = x;
    writer_->write(&pose, common::wall_now_ns());
  }

 private:
  std::unique_ptr<common::detail::WriterBackend> writer_;
};

TEST(Admission, OneSourceInOrderAndValidAnotherWriterAfterTheSourceFallsSilent) {
  using namespace std::chrono_literals;
  Participant a(in_process(9));
  Participant b(in_process(9));
  common::Admission<msg::DevicePose> admission{
      .takeover = 30ms,
      .valid =
          [](const msg::DevicePose& p) {
            return std::isfinite(p.world_from_stylus().position_m().x());
          },
      .counts = std::make_shared<common::AdmissionCounts>(),
      .wanted = {}};
  common::Subscriber<msg::DevicePose> sub(b, admission);
  ForgingWriter source(a);
  ForgingWriter intruder(a);
  source.write(1, 0.1);  // the first writer heard becomes the source
  ASSERT_TRUE(sub.fetch_newest());
  EXPECT_EQ(sub.newest().world_from_stylus().position_m().x(), 0.1);
  intruder.write(100, 9.0);  // another writer while the source lives
  source.write(1, 0.2);      // the source's sequence did not advance
  source.write(2, std::nan(""));
  EXPECT_FALSE(sub.fetch_newest());
  const auto& counts = sub.admission_counts();
  EXPECT_EQ(counts.foreign.load(), 1U);
  EXPECT_EQ(counts.out_of_order.load(), 1U);
  EXPECT_EQ(counts.invalid.load(), 1U);
  source.write(3, 0.3);
  ASSERT_TRUE(sub.fetch_newest());
  EXPECT_EQ(sub.newest().world_from_stylus().position_m().x(), 0.3);
  // The source silent past the takeover time: the next writer heard is
  // followed (a restarted service), and the old one is then foreign.
  std::this_thread::sleep_for(60ms);
  intruder.write(1, 0.4);
  ASSERT_TRUE(sub.fetch_newest());
  EXPECT_EQ(sub.newest().world_from_stylus().position_m().x(), 0.4);
  source.write(4, 0.5);
  EXPECT_FALSE(sub.fetch_newest());
  EXPECT_EQ(counts.source_changes.load(), 1U);
  EXPECT_EQ(counts.foreign.load(), 2U);
  // Without an Admission every sample gets in.
  common::Subscriber<msg::DevicePose> open(b);
  intruder.write(2, 0.6);
  source.write(5, 0.7);
  ASSERT_TRUE(open.fetch_newest());
  EXPECT_EQ(open.newest().world_from_stylus().position_m().x(), 0.7);
}

TEST(BackgroundPublisher, WritesTheNewestAndAccountsForEverySample) {
  Participant p(in_process(7));
  common::Subscriber<msg::ContactSet> sub(p);
  constexpr std::uint32_t kSamples = 500;
  std::uint64_t handed = 0;
  std::uint64_t written = 0;
  {
    common::BackgroundPublisher<msg::ContactSet> pub(p, std::chrono::microseconds(200), [] {
      msg::ContactSet c;
      c.contacts().reserve(msg::MAX_CONTACTS);
      return c;
    });
    for (std::uint32_t i = 1; i <= kSamples; ++i) {
      msg::ContactSet& c = pub.back();
      c.haptic_tick(i);
      c.contacts().resize(i % 64);  // the slot held an older sample: overwritten whole
      pub.publish();
    }
    // The thread writes the last one handed over, however many it skipped.
    std::uint64_t seen = 0;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (std::chrono::steady_clock::now() < deadline) {
      seen = sub.wait_for_samples(seen, std::chrono::milliseconds(50));
      if (sub.fetch_newest() && sub.newest().haptic_tick() == kSamples) break;
    }
    ASSERT_EQ(sub.newest().haptic_tick(), kSamples);
    EXPECT_EQ(sub.newest().contacts().size(), kSamples % 64);
    // The thread counts a write after the write returns, so the reader can see
    // the sample first (seen under load): wait, bounded, for the count.
    while (pub.written() < sub.newest_info().seq && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    handed = pub.handed();
    written = pub.written();
    EXPECT_EQ(pub.refused(), 0U);
  }  // joins the thread
  EXPECT_EQ(handed, kSamples);
  EXPECT_GE(written, 1U);
  EXPECT_LE(written, handed);
  EXPECT_EQ(sub.newest_info().seq, written) << "one write per sample written, none twice";
}

TEST(TickRecorder, DropsWhenFullInsteadOfBlocking) {
  common::TickRecorder recorder;
  for (std::size_t i = 0; i < common::TickRecorder::kCapacity + 10; ++i)
    recorder.push({i, 0, 0, 0});
  EXPECT_EQ(recorder.dropped(), 10U);
  std::size_t n = 0;
  recorder.drain([&](const common::TickRecord&) { ++n; });
  EXPECT_EQ(n, common::TickRecorder::kCapacity);
}

}  // namespace
}  // namespace fahr::test

namespace fahr::test {
namespace {

TEST(Config, ShippedProfilesLoad) {
  for (auto [vendor, file] : {std::pair{Vendor::kFastDds, "fastdds_loopback.xml"},
                              std::pair{Vendor::kCyclone, "cyclonedds_loopback.xml"}}) {
    TransportConfig config;
    config.vendor = vendor;
    config.domain_id = 18;
    config.profile_file = std::string(FAHR_DEPLOYMENT_DIR) + "/dds/" + file;
    EXPECT_NO_THROW(Participant p(config)) << file;
  }
}

// The UDP ports bound in this network namespace.
std::multiset<int> udp_ports() {
  std::multiset<int> ports;
  std::ifstream in("/proc/net/udp");
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string slot, local;
    words >> slot >> local;
    const std::size_t colon = local.find(':');
    if (colon != std::string::npos) ports.insert(std::stoi(local.substr(colon + 1), nullptr, 16));
  }
  return ports;
}

// A Fast DDS profile given to one participant applies to it only: the
// factory is the process's, and a later participant without a profile
// used to inherit it.
TEST(Config, FastDdsProfileStaysWithItsParticipant) {
  constexpr std::uint32_t kDomain = 211;
  constexpr int kFixedPort = 47123;
  const std::string file = ::testing::TempDir() + "fahr_fixed_discovery_port.xml";
  {
    std::ofstream out(file);
    out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
           "<profiles xmlns=\"http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles\">\n"
           "  <participant profile_name=\"fixed_port\" is_default_profile=\"true\">\n"
           "    <rtps><builtin><metatrafficUnicastLocatorList><locator><udpv4>\n"
           "      <address>127.0.0.1</address><port>"
        << kFixedPort
        << "</port>\n"
           "    </udpv4></locator></metatrafficUnicastLocatorList></builtin></rtps>\n"
           "  </participant>\n"
           "</profiles>\n";
  }
  TransportConfig with_profile;
  with_profile.vendor = Vendor::kFastDds;
  with_profile.domain_id = kDomain;
  with_profile.profile_file = file;
  TransportConfig plain = with_profile;
  plain.profile_file.clear();
  Participant a(with_profile);
  EXPECT_EQ(udp_ports().count(kFixedPort), 1U) << "the profile did not apply";
  Participant b(plain);
  const auto ports = udp_ports();
  EXPECT_EQ(ports.count(kFixedPort), 1U) << "the second participant took the first's profile";
  // b's discovery on the domain's RTPS default port (7400 + 250 d + 10 + 2 i).
  int defaults = 0;
  for (int i = 0; i < 120; ++i)
    defaults += static_cast<int>(ports.count(7400 + 250 * kDomain + 10 + 2 * i));
  EXPECT_GE(defaults, 1) << "the participant without a profile has no default discovery port";
}

}  // namespace
}  // namespace fahr::test
