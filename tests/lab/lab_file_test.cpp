// The lab file's loader, plan and generated configuration, without a network.
#include <gtest/gtest.h>

#include <string>

#include "fahr/lab_plan/lab.h"
#include "fahr/lab_plan/plan.h"
#include "fahr/lab_plan/profiles.h"

namespace fahr::lab {
namespace {

const std::string kScene = FAHR_SCENE_FILE;

std::string two_stations(const std::string& second_partition, const std::string& extra = "") {
  return "format_version: 1\n"
         "hosts:\n"
         "  - {name: a, address: 10.0.0.1, interface: eth0}\n"
         "  - {name: b, address: 10.0.0.2, interface: eth0}\n"
         "stations:\n"
         "  - name: one\n"
         "    domain: 5\n"
         "    scene: " +
         kScene +
         "\n"
         "    services:\n"
         "      fem: {host: b, vendor: fastdds}\n"
         "      haptic: {host: a}\n"
         "      device_gateway: {host: a}\n" +
         extra +
         "  - name: two\n"
         "    domain: 5\n"
         "    partition: " +
         second_partition +
         "\n"
         "    scene: " +
         kScene +
         "\n"
         "    services:\n"
         "      fem: {host: b}\n"
         "      haptic: {host: a}\n"
         "      device_gateway: {host: a}\n";
}

std::string first_issue(const std::string& text) {
  try {
    parse_lab(text, "lab.yaml", "/");
  } catch (const scene::SceneError& e) {
    return e.issues().front().to_string();
  }
  return "";
}

TEST(LabFile, TwoStationsOnOneDomainAndPartitionAreRefused) {
  EXPECT_NO_THROW(parse_lab(two_stations("two"), "lab.yaml", "/"));
  const std::string issue = first_issue(two_stations("one"));
  EXPECT_EQ(issue.rfind("lab.yaml:13:", 0), 0U) << issue;
  EXPECT_NE(issue.find("stations[1]"), std::string::npos) << issue;
  EXPECT_NE(issue.find("domain 5 and partition 'one'"), std::string::npos) << issue;
}

TEST(LabFile, ErrorsNameFileLineColumnAndKey) {
  std::string text = two_stations("two");
  text.replace(text.find("{host: b, vendor: fastdds}"), 26, "{host: c, vendor: fastdds}");
  const std::string issue = first_issue(text);
  EXPECT_EQ(issue.rfind("lab.yaml:10:", 0), 0U) << issue;
  EXPECT_NE(issue.find("stations[0].services.fem.host: no host 'c'"), std::string::npos) << issue;
  EXPECT_NE(first_issue(two_stations("two", "    colour: red\n")).find("colour"),
            std::string::npos);
}

TEST(LabFile, DiscoveryServerOnlyForFastDdsAlone) {
  const std::string issue =
      first_issue(two_stations("two", "    discovery: server\n    discovery_server_host: b\n"));
  EXPECT_NE(issue.find("serves Fast DDS only"), std::string::npos) << issue;
}

TEST(LabPlan, IndicesArePerHostAndDomainAndPeersCoverTheDomain) {
  const Lab lab = parse_lab(two_stations("two"), "lab.yaml", "/");
  const Plan plan = make_plan(lab);
  // Host a runs haptic and gateway of both stations on domain 5: 0..3.
  EXPECT_EQ(plan.find("one", ServiceKind::kHaptic)->index, 0);
  EXPECT_EQ(plan.find("two", ServiceKind::kDeviceGateway)->index, 3);
  EXPECT_EQ(plan.find("two", ServiceKind::kFem)->index, 1);
  EXPECT_EQ(discovery_port(5, 0), 7400 + 1250 + 10);
  const auto* fem = plan.find("one", ServiceKind::kFem);
  EXPECT_EQ(plan.peers(5, fem).size(), 5U);
  const std::string fast = fast_profile(plan, *fem);
  EXPECT_NE(fast.find("<participantID>0</participantID>"), std::string::npos);
  EXPECT_NE(fast.find("<address>10.0.0.2</address><port>8660</port>"), std::string::npos) << fast;
  EXPECT_NE(fast.find("<metatrafficUnicastLocatorList>"), std::string::npos);
  const std::string cyclone = cyclone_config(plan, *plan.find("one", ServiceKind::kHaptic));
  EXPECT_NE(cyclone.find("<AllowMulticast>false</AllowMulticast>"), std::string::npos);
  EXPECT_NE(cyclone.find("<ParticipantIndex>0</ParticipantIndex>"), std::string::npos);
  EXPECT_NE(cyclone.find("<Peer address=\"10.0.0.2:8660\"/>"), std::string::npos) << cyclone;
  EXPECT_NE(cyclone.find("NetworkInterface name=\"eth0\""), std::string::npos);
}

}  // namespace
}  // namespace fahr::lab
