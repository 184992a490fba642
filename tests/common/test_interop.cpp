// Fast DDS and Cyclone DDS exchange every topic type, both ways, with all
// fields intact: this process writes each type with one vendor, a peer
// process echoes it with the other (or the same) vendor, and the echo must
// equal the original byte for byte in CDR (the header's writer stamp aside).
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "fahr/common/publisher.h"
#include "fahr/common/subscriber.h"
#include "sample_factory.h"
#include "subprocess.h"
#include "test_topics.h"

namespace fahr::test {
namespace {

using common::Vendor;
using namespace std::chrono_literals;

struct VendorPair {
  Vendor local;
  Vendor peer;
  std::uint32_t domain;
};

std::string pair_name(const testing::TestParamInfo<VendorPair>& info) {
  return std::string(common::vendor_name(info.param.local)) + "_to_" +
         std::string(common::vendor_name(info.param.peer));
}

bool wait_until(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(5ms);
  }
  return true;
}

template <class T>
void expect_round_trip(common::Participant& participant, std::size_t sequence_length) {
  SCOPED_TRACE(std::string(common::TopicTraits<T>::kName));
  common::Publisher<T> ping(participant, test_qos(), ping_topic<T>());
  common::Subscriber<T> pong(participant, test_qos(), pong_topic<T>());
  ASSERT_TRUE(
      wait_until([&] { return ping.matched_readers() > 0 && pong.matched_writers() > 0; }, 15s))
      << "peer never matched";
  T sent;
  fill(sent, 42 + sequence_length, sequence_length);
  ASSERT_TRUE(ping.write(sent));
  ASSERT_GE(pong.wait_for_samples(0, 10s), 1U) << "no echo came back";
  ASSERT_TRUE(pong.fetch_newest());
  T echoed = pong.newest();
  // The echo keeps the simulated time and step; the writer stamp is its own.
  EXPECT_EQ(echoed.header().sim_time_ns(), sent.header().sim_time_ns());
  EXPECT_EQ(echoed.header().sim_step(), sent.header().sim_step());
  EXPECT_NE(echoed.header().writer_id(), sent.header().writer_id());
  echoed.header(sent.header());
  EXPECT_EQ(cdr_bytes(echoed), cdr_bytes(sent));
}

class Interop : public testing::TestWithParam<VendorPair> {};

TEST_P(Interop, EveryTopicTypeCrossesIntact) {
  const VendorPair pair = GetParam();
  Subprocess peer({executable_dir() + "/transport_peer", "echo",
                   std::string(common::vendor_name(pair.peer)), std::to_string(pair.domain), "60"});
  common::TransportConfig config;
  config.vendor = pair.local;
  config.domain_id = pair.domain;
  config.participant_name = "test_interop";
  common::Participant participant(config);
  expect_round_trip<msg::DevicePose>(participant, 0);
  expect_round_trip<msg::ForceCommand>(participant, 0);
  expect_round_trip<msg::ContactSet>(participant, 100);
  // ~60 KiB of nodes and a full compliance block: fragmented on the wire.
  expect_round_trip<msg::DeformationState>(participant, 5000);
  expect_round_trip<msg::SceneDescription>(participant, 2000);
  expect_round_trip<msg::ServiceStatus>(participant, 32);
  expect_round_trip<msg::ServiceEvents>(participant, 200);
  expect_round_trip<msg::SimClock>(participant, 0);
  expect_round_trip<msg::StepAck>(participant, 0);
  expect_round_trip<msg::GlotticView>(participant, 0);
}

INSTANTIATE_TEST_SUITE_P(Vendors, Interop,
                         testing::Values(VendorPair{Vendor::kFastDds, Vendor::kFastDds, 11},
                                         VendorPair{Vendor::kCyclone, Vendor::kCyclone, 12},
                                         VendorPair{Vendor::kFastDds, Vendor::kCyclone, 13},
                                         VendorPair{Vendor::kCyclone, Vendor::kFastDds, 14}),
                         pair_name);

}  // namespace
}  // namespace fahr::test
