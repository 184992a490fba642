// Flag parsing for the gateway main (hand-written: a dozen flags do not need
// a dependency).
#include "fahr/gateway_service/gateway_options.h"

#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "fahr/device/trajectory.h"

namespace fahr::gateway_service {

namespace {

constexpr const char* kUsage =
    "usage: fahr_device_gateway [--dds fastdds|cyclonedds|inprocess] [--domain N] [--dds-profile "
    "FILE] [--security DIR]\n"
    "         [--mode realtime|lockstep] [--backend simulated|replay|remote|openhaptics]\n"
    "         [--script intubation|overshoot] [--model touch_x|touch] [--duration-s S]\n"
    "         [--replay-file FILE] [--record-file FILE] [--device-id N] [--rt-priority 1-99]\n"
    "         [--spin-us N] [--status-hz HZ] [--force-input-period N] [--wait-haptic-s S]\n";

bool parse_number(std::string_view flag, const char* text, double& out) {
  char* end = nullptr;
  out = std::strtod(text, &end);
  if (end == text || *end != '\0') {
    std::fprintf(stderr, "fahr_device_gateway: %.*s: '%s' is not a number\n",
                 static_cast<int>(flag.size()), flag.data(), text);
    return false;
  }
  return true;
}

bool in_set(std::string_view value, std::initializer_list<std::string_view> allowed) {
  for (auto a : allowed) {
    if (value == a) return true;
  }
  return false;
}

}  // namespace

std::optional<GatewayOptions> parse_options(int argc, char** argv) {
  GatewayOptions o;
  for (int i = 1; i < argc; ++i) {
    const std::string_view flag = argv[i];
    if (flag == "--help" || flag == "-h") {
      std::fputs(kUsage, stderr);
      return std::nullopt;
    }
    if (i + 1 >= argc) {
      std::fprintf(stderr, "fahr_device_gateway: %s needs a value\n%s", argv[i], kUsage);
      return std::nullopt;
    }
    const char* value = argv[++i];
    double number = 0.0;
    bool ok = true;
    if (flag == "--dds")
      o.dds = value;
    else if (flag == "--domain")
      o.domain = value;
    else if (flag == "--dds-profile" || flag == "--profile")
      o.profile = value;
    else if (flag == "--security")
      o.security = value;
    else if (flag == "--mode")
      o.mode = value;
    else if (flag == "--backend")
      o.backend = value;
    else if (flag == "--script")
      o.script = value;
    else if (flag == "--model")
      o.model = value;
    else if (flag == "--replay-file")
      o.replay_file = value;
    else if (flag == "--record-file")
      o.record_file = value;
    else if (flag == "--duration-s")
      ok = parse_number(flag, value, o.duration_s) && o.duration_s >= 0.0;
    else if (flag == "--wait-haptic-s")
      ok = parse_number(flag, value, o.wait_haptic_s) && o.wait_haptic_s >= 0.0 &&
           o.wait_haptic_s <= 3600.0;
    else if (flag == "--status-hz")
      ok = parse_number(flag, value, o.status_hz) && o.status_hz > 0.0 && o.status_hz <= 100.0;
    else if (flag == "--device-id" || flag == "--rt-priority" || flag == "--spin-us" ||
             flag == "--force-input-period") {
      ok = parse_number(flag, value, number) && number >= 0.0 && number < 1e9;
      if (flag == "--device-id") o.device_id = static_cast<std::uint32_t>(number);
      if (flag == "--rt-priority") o.rt_priority = static_cast<int>(number);
      if (flag == "--spin-us") o.spin_us = static_cast<int>(number);
      if (flag == "--force-input-period") o.force_input_period = static_cast<std::uint64_t>(number);
    } else {
      std::fprintf(stderr, "fahr_device_gateway: unknown flag %s\n%s", argv[i - 1], kUsage);
      return std::nullopt;
    }
    if (!ok) {
      std::fprintf(stderr, "fahr_device_gateway: %s: bad value '%s'\n", argv[i - 1], value);
      return std::nullopt;
    }
  }
  const auto reject = [](const char* flag, const std::string& value) {
    std::fprintf(stderr, "fahr_device_gateway: %s: unknown value '%s'\n%s", flag, value.c_str(),
                 kUsage);
    return std::nullopt;
  };
  if (!in_set(o.mode, {"realtime", "lockstep"})) return reject("--mode", o.mode);
  if (!in_set(o.backend, {"simulated", "replay", "remote", "openhaptics"}))
    return reject("--backend", o.backend);
  if (device::Script script{}; !device::script_by_name(o.script, script))
    return reject("--script", o.script);
  if (o.backend == "replay" && o.replay_file.empty())
    return reject("--replay-file", "(missing: replay needs a file)");
  if (o.rt_priority > 99) return reject("--rt-priority", std::to_string(o.rt_priority));
  return o;
}

}  // namespace fahr::gateway_service
