// The spelling of every enumeration in scene files: one table per enum, read
// by the parser (text to value) and by to_string (value to text).
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "fahr/scene/body.h"
#include "fahr/scene/contact_settings.h"
#include "fahr/scene/device_settings.h"
#include "fahr/scene/plan.h"
#include "fahr/scene/qos_override.h"
#include "fahr/scene/run_settings.h"
#include "fahr/scene/solver_settings.h"

namespace fahr::scene::detail {

template <typename E, std::size_t N>
using NameTable = std::pair<std::string_view, E>[N];

inline constexpr std::pair<std::string_view, BodyRole> kBodyRoleNames[] = {
    {"deformable", BodyRole::kDeformable},
    {"tool", BodyRole::kTool},
    {"obstacle", BodyRole::kObstacle}};
inline constexpr std::pair<std::string_view, LengthUnit> kLengthUnitNames[] = {
    {"m", LengthUnit::kMetre}, {"cm", LengthUnit::kCentimetre}, {"mm", LengthUnit::kMillimetre}};
inline constexpr std::pair<std::string_view, MaterialModel> kMaterialModelNames[] = {
    {"corotational", MaterialModel::kCorotational},
    {"stable_neo_hookean", MaterialModel::kStableNeoHookean}};
inline constexpr std::pair<std::string_view, RunMode> kRunModeNames[] = {
    {"realtime", RunMode::kRealtime}, {"lockstep", RunMode::kLockstep}};
inline constexpr std::pair<std::string_view, DdsVendor> kDdsVendorNames[] = {
    {"cyclonedds", DdsVendor::kCycloneDds}, {"fastdds", DdsVendor::kFastDds}};
inline constexpr std::pair<std::string_view, DeviceBackend> kDeviceBackendNames[] = {
    {"simulated", DeviceBackend::kSimulated},
    {"replay", DeviceBackend::kReplay},
    {"remote", DeviceBackend::kRemote},
    {"openhaptics", DeviceBackend::kOpenHaptics}};
inline constexpr std::pair<std::string_view, DeviceModel> kDeviceModelNames[] = {
    {"touch_x", DeviceModel::kTouchX}, {"custom", DeviceModel::kCustom}};
inline constexpr std::pair<std::string_view, DeviceScript> kDeviceScriptNames[] = {
    {"intubation", DeviceScript::kIntubation}, {"overshoot", DeviceScript::kOvershoot}};
inline constexpr std::pair<std::string_view, LinearSolver> kLinearSolverNames[] = {
    {"cholmod", LinearSolver::kCholmod}, {"pcg", LinearSolver::kPcg}};
inline constexpr std::pair<std::string_view, ComplianceMode> kComplianceModeNames[] = {
    {"exact", ComplianceMode::kExact},
    {"lagged", ComplianceMode::kLagged},
    {"none", ComplianceMode::kNone}};
inline constexpr std::pair<std::string_view, ComplianceColumns> kComplianceColumnsNames[] = {
    {"blocks", ComplianceColumns::kBlocks}, {"normals", ComplianceColumns::kNormals}};
inline constexpr std::pair<std::string_view, ContactResponse> kContactResponseNames[] = {
    {"force_aware", ContactResponse::kForceAware}, {"penalty", ContactResponse::kPenalty}};
inline constexpr std::pair<std::string_view, HeldProxy> kHeldProxyNames[] = {
    {"load", HeldProxy::kLoad}, {"stay", HeldProxy::kStay}};
inline constexpr std::pair<std::string_view, Reliability> kReliabilityNames[] = {
    {"reliable", Reliability::kReliable}, {"best_effort", Reliability::kBestEffort}};
inline constexpr std::pair<std::string_view, PairKind> kPairKindNames[] = {
    {"tool", PairKind::kTool}, {"hard", PairKind::kHard}};
inline constexpr std::pair<std::string_view, PairReason> kPairReasonNames[] = {
    {"tool_deformable", PairReason::kToolDeformable},
    {"tool_obstacle", PairReason::kToolObstacle},
    {"declared", PairReason::kDeclared},
    {"within_margin", PairReason::kWithinMargin},
    {"bounds_unknown", PairReason::kBoundsUnknown}};

template <typename E, std::size_t N>
std::string_view name_of(const NameTable<E, N>& table, E value) {
  for (const auto& [name, candidate] : table) {
    if (candidate == value) return name;
  }
  return "?";
}

template <typename E, std::size_t N>
std::optional<E> value_of(const NameTable<E, N>& table, std::string_view name) {
  for (const auto& [candidate, value] : table) {
    if (candidate == name) return value;
  }
  return std::nullopt;
}

// "a, b, c": the valid spellings, for error messages.
template <typename E, std::size_t N>
std::string names_listed(const NameTable<E, N>& table) {
  std::string out;
  for (const auto& entry : table) {
    if (!out.empty()) out += ", ";
    out += entry.first;
  }
  return out;
}

}  // namespace fahr::scene::detail
