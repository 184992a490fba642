// The transport settings of a service started on a scene: each value from
// its flag, else its environment variable (FAHR_DDS, FAHR_DOMAIN_ID,
// FAHR_DDS_PROFILE), else the scene's `dds` section.
#pragma once

#include <string>

#include "fahr/common/transport_config.h"
#include "fahr/scene/scene.h"

namespace fahr::runtime {

// Throws common::ConfigError naming the flag, variable or value at fault.
common::TransportConfig transport_for(const scene::Scene& scene, const std::string& dds_flag,
                                      const std::string& domain_flag,
                                      const std::string& profile_flag, std::string participant_name,
                                      const std::string& security_flag = {});

}  // namespace fahr::runtime
