// Flag > environment > scene.
#include "fahr/runtime/scene_transport.h"

#include <cstdlib>

namespace fahr::runtime {

common::TransportConfig transport_for(const scene::Scene& scene, const std::string& dds_flag,
                                      const std::string& domain_flag,
                                      const std::string& profile_flag, std::string participant_name,
                                      const std::string& security_flag) {
  std::string vendor = dds_flag;
  if (vendor.empty() && std::getenv("FAHR_DDS") == nullptr) {
    vendor = scene.dds.vendor == scene::DdsVendor::kFastDds ? "fastdds" : "cyclonedds";
  }
  std::string domain = domain_flag;
  if (domain.empty() && std::getenv("FAHR_DOMAIN_ID") == nullptr)
    domain = std::to_string(scene.dds.domain_id);
  return common::transport_config_from(vendor, domain, profile_flag, std::move(participant_name),
                                       security_flag);
}

}  // namespace fahr::runtime
