// to_string of every public enumeration, from the tables the parser reads.
#include "enum_names.h"

namespace fahr::scene {

using detail::name_of;

std::string_view to_string(BodyRole role) {
  return name_of(detail::kBodyRoleNames, role);
}
std::string_view to_string(LengthUnit unit) {
  return name_of(detail::kLengthUnitNames, unit);
}
std::string_view to_string(MaterialModel model) {
  return name_of(detail::kMaterialModelNames, model);
}
std::string_view to_string(RunMode mode) {
  return name_of(detail::kRunModeNames, mode);
}
std::string_view to_string(DdsVendor vendor) {
  return name_of(detail::kDdsVendorNames, vendor);
}
std::string_view to_string(DeviceBackend backend) {
  return name_of(detail::kDeviceBackendNames, backend);
}
std::string_view to_string(DeviceModel model) {
  return name_of(detail::kDeviceModelNames, model);
}
std::string_view to_string(DeviceScript script) {
  return name_of(detail::kDeviceScriptNames, script);
}
std::string_view to_string(LinearSolver solver) {
  return name_of(detail::kLinearSolverNames, solver);
}
std::string_view to_string(ComplianceColumns columns) {
  return name_of(detail::kComplianceColumnsNames, columns);
}
std::string_view to_string(ComplianceMode mode) {
  return name_of(detail::kComplianceModeNames, mode);
}
std::string_view to_string(ContactResponse response) {
  return name_of(detail::kContactResponseNames, response);
}
std::string_view to_string(HeldProxy held) {
  return name_of(detail::kHeldProxyNames, held);
}
std::string_view to_string(Reliability reliability) {
  return name_of(detail::kReliabilityNames, reliability);
}
std::string_view to_string(PairKind kind) {
  return name_of(detail::kPairKindNames, kind);
}
std::string_view to_string(PairReason reason) {
  return name_of(detail::kPairReasonNames, reason);
}

}  // namespace fahr::scene
