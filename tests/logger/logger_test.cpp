// The recorder in one process on the in-process bus: what it writes (one
// channel per topic and key, the CDR bytes, times and sequences, omgidl
// schemas) and its books (recorded + gaps + drops = sent) with and without
// a queue that overflows.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <thread>

#include "fahr/common/publisher.h"
#include "fahr/common/service_reporter.h"
#include "fahr/common/wire_header.h"
#include "fahr/logger_service/loss_accounting.h"
#include "fahr/logger_service/recorder.h"
#include "fahr/mcap/reader.h"
#include "sample_factory.h"

namespace fahr::logger_service {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

common::TransportConfig in_process(std::uint32_t domain, const char* name) {
  common::TransportConfig config;
  config.vendor = common::Vendor::kInProcess;
  config.domain_id = domain;
  config.participant_name = name;
  return config;
}

fs::path temp_dir() {
  return fs::temp_directory_path() / ("fahr_logger_test_" + std::to_string(getpid()));
}

std::string temp_file(const std::string& name) {
  fs::create_directories(temp_dir());
  return (temp_dir() / name).string();
}

// Removes the test's recordings when the binary ends.
class TempFiles : public ::testing::Environment {
 public:
  void TearDown() override { fs::remove_all(temp_dir()); }
};
const auto* const kTempFiles = ::testing::AddGlobalTestEnvironment(new TempFiles);

TEST(WireHeader, ReadsSequenceWriterAndKeyFromTheBytes) {
  msg::DevicePose pose;
  test::fill(pose, 7, 3);
  pose.header().seq(123456789012ULL);
  pose.header().writer_id(0xdeadbeefU);
  pose.header().source_time_ns(-42);
  pose.device_id(17);
  const auto bytes = test::cdr_bytes(pose);
  const auto h = common::read_wire_header(bytes, true);
  ASSERT_TRUE(h.has_value());
  EXPECT_EQ(h->seq, 123456789012ULL);
  EXPECT_EQ(h->writer_id, 0xdeadbeefU);
  EXPECT_EQ(h->source_time_ns, -42);
  EXPECT_EQ(h->key, 17U);
  EXPECT_FALSE(common::read_wire_header(std::span(bytes).first(20), true).has_value());
}

TEST(LossAccounting, GapsLateSamplesAndTheWritersOwnCountCloseTheBooks) {
  LossAccounting books;
  for (std::uint64_t seq : {1, 2, 5, 4, 7}) books.on_receive("t", 9, seq);
  books.on_drop("t", 9);
  for (int i = 0; i < 4; ++i) books.on_recorded("t", 9);
  books.on_reported_sent("t", 9, 9);
  const auto t = books.snapshot().at(0);
  EXPECT_EQ(t.late, 1U);
  EXPECT_EQ(t.sent(), 9U);
  EXPECT_EQ(t.total_gaps(), 4U);  // 3, 6 and 8, 9 after the last one seen
  EXPECT_EQ(t.recorded + t.total_gaps() + t.drops, t.sent());
  // A restarted writer (new id) has books of its own.
  books.on_receive("t", 10, 1);
  EXPECT_EQ(books.snapshot().size(), 2U);
}

struct Recording {
  std::string path;
  std::vector<WriterTally> tallies;
  RecorderStats stats;
};

// Publishes `poses` DevicePoses alternating over devices 0 and 1, two
// DeformationStates and a ServiceStatus with the sent counts, recorded by a
// Recorder on another participant.
Recording record(std::uint32_t domain, const std::string& name, int poses, RecorderOptions options,
                 std::vector<std::uint8_t>* last_pose_bytes = nullptr) {
  common::Participant recorder_side(in_process(domain, "logger"));
  common::Participant service(in_process(domain, "service"));
  options.path = temp_file(name);
  options.mcap.sync_chunks = false;
  options.mcap.chunk_size = 4096;
  Recording out;
  out.path = options.path;
  Recorder recorder(recorder_side, options);
  {
    common::TickRecorder ticks;
    common::ServiceReporter reporter(service, {"test_service", 1000.0, 10s}, ticks);
    common::Publisher<msg::DevicePose> pose_out(service);
    common::Publisher<msg::DeformationState> state_out(service);
    msg::DevicePose pose;
    test::fill(pose, 1, 2);
    for (int i = 0; i < poses; ++i) {
      pose.device_id(static_cast<std::uint32_t>(i % 2));
      pose.servo_tick(static_cast<std::uint64_t>(i));
      pose_out.write(pose);
    }
    if (last_pose_bytes != nullptr) *last_pose_bytes = test::cdr_bytes(pose);
    msg::DeformationState state;
    test::fill(state, 2, 300);
    state.body_id(3);
    state_out.write(state);
    state_out.write(state);
    reporter.report();
  }
  recorder.stop();
  out.tallies = recorder.tallies();
  out.stats = recorder.stats();
  return out;
}

TEST(Recorder, OneChannelPerTopicAndKeyWithTheBytesTimesAndSequences) {
  std::vector<std::uint8_t> last_pose;
  const auto rec = record(201, "plain.mcap", 100, {}, &last_pose);
  std::map<std::string, std::uint64_t> per_key;
  std::uint32_t last_seq = 0;
  bool bytes_equal = false;
  const auto r = mcap::read_file(rec.path, [&](const mcap::Channel& c, const mcap::MessageView& m) {
    const auto it = c.metadata.find("key");
    per_key[c.topic + (it == c.metadata.end() ? "" : " " + it->second)]++;
    if (c.topic == "fahr/DevicePose") {
      EXPECT_EQ(m.sequence, last_seq + 1);
      last_seq = m.sequence;
      EXPECT_LE(m.publish_time, m.log_time);
      const auto h = common::read_wire_header(m.data, true);
      ASSERT_TRUE(h.has_value());
      EXPECT_EQ(static_cast<std::uint64_t>(h->source_time_ns), m.publish_time);
      bytes_equal = std::equal(m.data.begin(), m.data.end(), last_pose.begin(), last_pose.end());
    }
  });
  EXPECT_TRUE(r.valid()) << r.error;
  EXPECT_TRUE(bytes_equal) << "the last DevicePose's bytes differ from its CDR serialisation";
  EXPECT_EQ(per_key["fahr/DevicePose device_id=0"], 50U);
  EXPECT_EQ(per_key["fahr/DevicePose device_id=1"], 50U);
  EXPECT_EQ(per_key["fahr/DeformationState body_id=3"], 2U);
  EXPECT_EQ(r.schemas.size(), 10U);
  for (const auto& [id, s] : r.schemas) {
    EXPECT_EQ(s.encoding, "omgidl");
    EXPECT_EQ(s.name.rfind("fahr::msg::", 0), 0U);
    EXPECT_EQ(s.data.find('#'), std::string::npos) << s.name;
  }
  ASSERT_EQ(r.metadata.size(), 3U);
  EXPECT_EQ(r.metadata[0].name, "fahr_run");
  EXPECT_EQ(r.metadata[2].name, "fahr_recording_loss");
  for (const auto& t : rec.tallies) {
    EXPECT_EQ(t.recorded + t.total_gaps() + t.drops, t.sent()) << t.topic;
    EXPECT_EQ(t.drops, 0U);
    if (t.topic == "fahr/DevicePose") {
      EXPECT_EQ(t.sent(), 100U);
      EXPECT_EQ(t.reported_sent, 100U);
      EXPECT_EQ(t.recorded, 100U);
    }
  }
}

TEST(Recorder, AnOverflowingQueueDropsAndCountsEveryDrop) {
  RecorderOptions options;
  options.queue_bytes = 4000;  // about 15 DevicePoses
  options.writer_delay = 2ms;
  const auto rec = record(202, "overflow.mcap", 400, options);
  std::uint64_t in_file = 0;
  const auto r = mcap::read_file(rec.path, [&](const mcap::Channel& c, const mcap::MessageView&) {
    if (c.topic == "fahr/DevicePose") ++in_file;
  });
  EXPECT_TRUE(r.valid()) << r.error;
  EXPECT_GT(rec.stats.dropped, 0U);
  bool found = false;
  for (const auto& t : rec.tallies) {
    EXPECT_EQ(t.recorded + t.total_gaps() + t.drops, t.sent()) << t.topic;
    if (t.topic != "fahr/DevicePose") continue;
    found = true;
    EXPECT_GT(t.drops, 0U);
    EXPECT_EQ(t.total_gaps(), 0U);
    EXPECT_EQ(t.recorded, in_file);
    EXPECT_EQ(t.sent(), 400U);
  }
  EXPECT_TRUE(found);
}

TEST(Recorder, DecimationSkipsAndCountsTheSkipped) {
  RecorderOptions options;
  options.decimate["fahr/DevicePose"] = 10;
  const auto rec = record(203, "decimated.mcap", 100, options);
  for (const auto& t : rec.tallies) {
    if (t.topic != "fahr/DevicePose") continue;
    EXPECT_EQ(t.recorded, 10U);
    EXPECT_EQ(t.skipped, 90U);
    EXPECT_EQ(t.recorded + t.skipped + t.total_gaps() + t.drops, t.sent());
  }
}

}  // namespace
}  // namespace fahr::logger_service
