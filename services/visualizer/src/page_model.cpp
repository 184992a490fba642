// Slots -> page frames.
#include "fahr/visualizer_service/page_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>

#include "contact_setPubSubTypes.h"
#include "deformation_statePubSubTypes.h"
#include "device_posePubSubTypes.h"
#include "fahr/common/cdr_bytes.h"
#include "fahr/fem/strain.h"
#include "fahr/geometry/surface_loader.h"
#include "fahr/geometry/tet_deformation.h"
#include "force_commandPubSubTypes.h"
#include "glottic_viewPubSubTypes.h"
#include "scene_descriptionPubSubTypes.h"
#include "service_statusPubSubTypes.h"

namespace fahr::visualizer_service {
namespace {

using nlohmann::json;

// Appends little-endian words and float arrays (x86-64 and every target of
// fahr are little endian; the page reads them with typed-array views).
struct Out {
  std::string s;
  void u32(std::uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); }
  void f64(double v) { s.append(reinterpret_cast<const char*>(&v), 8); }
  void f32(float v) { s.append(reinterpret_cast<const char*>(&v), 4); }
  template <class T>
  void array(const T* p, std::size_t n) {
    s.append(reinterpret_cast<const char*>(p), n * sizeof(T));
  }
  void pad4() {
    while (s.size() % 4 != 0) s.push_back('\0');
  }
};

std::uint32_t role_code(scene::BodyRole role) {
  switch (role) {
    case scene::BodyRole::kDeformable:
      return 0;
    case scene::BodyRole::kTool:
      return 1;
    case scene::BodyRole::kObstacle:
      break;
  }
  return 2;
}

json vec(const msg::Vec3& v) {
  return json::array({v.x(), v.y(), v.z()});
}
json quat(const msg::Quat& q) {
  return json::array({q.w(), q.x(), q.y(), q.z()});
}
json pose(const msg::Pose& p) {
  return json{{"p", vec(p.position_m())}, {"q", quat(p.orientation())}};
}
double norm(const msg::Vec3& v) {
  return std::sqrt(v.x() * v.x() + v.y() * v.y() + v.z() * v.z());
}
double finite_or_zero(double v) {
  return std::isfinite(v) ? v : 0.0;
}

// JSON numbers must be finite; a NaN would make the frame unparseable.
void scrub(json& j) {
  if (j.is_number_float()) {
    j = finite_or_zero(j.get<double>());
  } else if (j.is_structured()) {
    for (auto& e : j) scrub(e);
  }
}

}  // namespace

PageModel::PageModel(std::shared_ptr<const scene::Scene> scene) : scene_(std::move(scene)) {
  add_rigid_bodies();
}

FramePtr PageModel::make(int stream, bool binary, bool sticky, std::string data) {
  auto f = std::make_shared<Frame>();
  f->binary = binary;
  f->sticky = sticky;
  f->version = next_version_++;
  f->data = std::move(data);
  frames_[stream] = f;
  return f;
}

void PageModel::add_rigid_bodies() {
  if (!scene_) return;
  for (const auto& body : scene_->bodies) {
    if (body.role == scene::BodyRole::kDeformable) continue;
    geometry::SurfaceMesh mesh;
    try {
      mesh = geometry::load_surface(body.mesh_path, body.mesh_scale);
    } catch (const std::exception&) {
      continue;  // a body without its mesh is not drawn; the rest still is
    }
    Out o;
    o.u32(kSceneFrame);
    o.u32(body.id);
    o.u32(role_code(body.role));
    o.u32(static_cast<std::uint32_t>(mesh.vertex_count()));
    o.u32(static_cast<std::uint32_t>(mesh.triangle_count()));
    o.u32(0);  // spheres
    o.u32(static_cast<std::uint32_t>(body.name.size()));
    o.s += body.name;
    o.pad4();
    // Obstacles in the world frame; the tool in its own, posed by the page.
    const bool world = body.role == scene::BodyRole::kObstacle;
    for (const auto& v : mesh.vertices()) {
      const Eigen::Vector3d w =
          world ? Eigen::Vector3d(body.pose.orientation * v + body.pose.position_m) : v;
      for (int k = 0; k < 3; ++k) o.f32(static_cast<float>(w[k]));
    }
    for (const auto& t : mesh.triangles()) {
      for (int k = 0; k < 3; ++k) o.u32(static_cast<std::uint32_t>(t[k]));
    }
    make(kSceneStreamBase + static_cast<int>(body.id), true, true, std::move(o.s));
  }
}

void PageModel::on_scene(const Slot& slot) {
  msg::SceneDescription d;
  if (!common::decode_cdr<msg::SceneDescriptionPubSubType>(slot.bytes, d)) return;
  if (d.role() != msg::BODY_DEFORMABLE) return;  // rigid meshes come from the scene file
  const auto& rest = d.rest_positions_m();
  const auto& tets = d.tets();
  const std::size_t nodes = rest.size() / 3;
  Deformable def;
  def.body_id = d.body_id();
  def.nodes = nodes;
  std::vector<Eigen::Vector3d> rest_m(nodes);
  for (std::size_t i = 0; i < nodes; ++i)
    rest_m[i] = {rest[3 * i], rest[3 * i + 1], rest[3 * i + 2]};
  std::vector<fem::Tet> tet_list;
  for (std::size_t t = 0; t + 3 < tets.size(); t += 4) {
    const fem::Tet tet{tets[t], tets[t + 1], tets[t + 2], tets[t + 3]};
    if (std::any_of(tet.begin(), tet.end(), [&](std::uint32_t n) { return n >= nodes; })) return;
    tet_list.push_back(tet);
  }
  if (!fem::build_element_rest(rest_m, tet_list, def.rest).empty()) def.rest = {};
  def.node_tets.assign(nodes, {});
  for (std::size_t t = 0; t < def.rest.size(); ++t) {
    for (auto n : def.rest.tets[t]) def.node_tets[n].push_back(static_cast<std::uint32_t>(t));
  }
  const auto& tris = d.triangles();
  const std::size_t n_tris = tris.size() / 3;
  for (std::size_t i = 0; i < n_tris * 3; ++i) {
    if (tris[i] >= nodes) return;
  }
  const auto& spheres = d.sphere_rest_m();
  Out o;
  o.u32(kSceneFrame);
  o.u32(d.body_id());
  o.u32(0);
  o.u32(static_cast<std::uint32_t>(nodes));
  o.u32(static_cast<std::uint32_t>(n_tris));
  o.u32(static_cast<std::uint32_t>(spheres.size() / 4));
  o.u32(static_cast<std::uint32_t>(d.body_name().size()));
  o.s += d.body_name();
  o.pad4();
  o.array(rest.data(), nodes * 3);
  o.array(tris.data(), n_tris * 3);
  const std::size_t n_spheres = spheres.size() / 4;
  o.array(spheres.data(), n_spheres * 4);
  // The spheres' node links and levels, so the page moves them with the
  // tissue (c = sum w x, the layout's own definition) and shows levels
  // apart. Links that do not fit the mesh are left out: spheres at rest.
  const auto& offsets = d.sphere_link_offsets();
  const auto& link_nodes = d.sphere_nodes();
  const auto& weights = d.sphere_weights();
  bool links_ok = offsets.size() == n_spheres && link_nodes.size() == weights.size() &&
                  d.sphere_levels().size() == n_spheres;
  for (std::size_t i = 0; links_ok && i < n_spheres; ++i) {
    const std::size_t end = i + 1 < n_spheres ? offsets[i + 1] : link_nodes.size();
    links_ok = offsets[i] <= end && end <= link_nodes.size();
  }
  for (std::size_t k = 0; links_ok && k < link_nodes.size(); ++k) {
    links_ok = link_nodes[k] < nodes && std::isfinite(weights[k]);
  }
  if (links_ok) {
    o.u32(static_cast<std::uint32_t>(link_nodes.size()));
    o.array(offsets.data(), n_spheres);
    o.array(link_nodes.data(), link_nodes.size());
    o.array(weights.data(), weights.size());
    o.array(d.sphere_levels().data(), n_spheres);
    o.pad4();
  } else {
    o.u32(0);
  }
  deformables_[d.body_id()] = std::move(def);
  make(kSceneStreamBase + static_cast<int>(d.body_id()), true, true, std::move(o.s));
}

void PageModel::on_deformation(const Slot& slot) {
  msg::DeformationState s;
  if (!common::decode_cdr<msg::DeformationStatePubSubType>(slot.bytes, s)) return;
  auto it = deformables_.find(s.body_id());
  if (it == deformables_.end()) return;  // its scene has not arrived yet
  const Deformable& def = it->second;
  const auto& p = s.positions_m();
  if (p.size() != def.nodes * 3) return;
  positions_.assign(p.begin(), p.end());
  tet_strain_.assign(def.rest.size(), 0.0);
  for (std::size_t t = 0; t < def.rest.size(); ++t) {
    const Eigen::Matrix3d f =
        geometry::deformation_gradient(positions_.data(), def.rest.tets[t], def.rest.dm_inv[t]);
    tet_strain_[t] = fem::principal_green_strain(f);
  }
  Out o;
  o.s.reserve(16 + 8 + def.nodes * 16);
  o.u32(kDeformationFrame);
  o.u32(s.body_id());
  o.u32(static_cast<std::uint32_t>(def.nodes));
  o.u32(0);
  o.f64(static_cast<double>(s.header().sim_time_ns()) * 1e-9);
  o.array(p.data(), p.size());
  max_node_strain_ = 0;
  for (std::size_t n = 0; n < def.nodes; ++n) {
    double e = 0;
    for (auto t : def.node_tets[n]) e = std::max(e, tet_strain_[t]);
    if (!std::isfinite(e)) e = 0;
    max_node_strain_ = std::max(max_node_strain_, e);
    o.f32(static_cast<float>(e));
  }
  make(kDeformStreamBase + static_cast<int>(s.body_id()), true, false, std::move(o.s));
}

void PageModel::update(const std::vector<Slot>& slots, const std::string& mode) {
  if (seen_.size() < slots.size()) seen_.resize(slots.size(), 0);
  for (std::size_t i = 0; i < slots.size(); ++i) {
    const Slot& slot = slots[i];
    if (slot.version == seen_[i]) continue;
    seen_[i] = slot.version;
    state_dirty_ = true;
    if (slot.bytes.empty()) {
      pieces_.erase(i);
      continue;
    }
    json j;
    switch (slot.topic) {
      case kSceneDescription:
        on_scene(slot);
        break;
      case kDeformationState:
        on_deformation(slot);
        break;
      case kDevicePose: {
        msg::DevicePose m;
        if (!common::decode_cdr<msg::DevicePosePubSubType>(slot.bytes, m)) break;
        j = {{"id", m.device_id()},
             {"t", static_cast<double>(m.header().sim_time_ns()) * 1e-9},
             {"pose", pose(m.world_from_stylus())},
             {"safety", static_cast<int>(m.safety_state())},
             {"limit_n", m.renderable_force_n()},
             {"rendered_n", vec(m.rendered_force_n())}};
        break;
      }
      case kForceCommand: {
        msg::ForceCommand m;
        if (!common::decode_cdr<msg::ForceCommandPubSubType>(slot.bytes, m)) break;
        j = {{"id", m.device_id()},
             {"t", static_cast<double>(m.header().sim_time_ns()) * 1e-9},
             {"proxy", pose(m.world_from_proxy())},
             {"force", vec(m.force_n())},
             {"force_n", norm(m.force_n())},
             {"lost_track", m.lost_track()},
             {"device_minus_proxy", vec(m.device_minus_proxy_m())},
             {"tissue_n", m.tissue_reaction_n()},
             {"active_contacts", m.active_contacts()},
             {"source_ns", m.header().source_time_ns()}};
        break;
      }
      case kContactSet: {
        msg::ContactSet m;
        if (!common::decode_cdr<msg::ContactSetPubSubType>(slot.bytes, m)) break;
        json list = json::array();
        for (const auto& c : m.contacts()) {
          list.push_back({c.sphere_id(), static_cast<int>(c.kind()), static_cast<int>(c.state()),
                          c.point_m().x(), c.point_m().y(), c.point_m().z(), c.normal().x(),
                          c.normal().y(), c.normal().z(), c.force_n()});
        }
        j = {{"body", m.body_id()}, {"frozen", m.tool_frozen()}, {"contacts", std::move(list)}};
        break;
      }
      case kServiceStatus: {
        msg::ServiceStatus m;
        if (!common::decode_cdr<msg::ServiceStatusPubSubType>(slot.bytes, m)) break;
        json metrics = json::object();
        for (const auto& metric : m.metrics()) metrics[std::string(metric.name())] = metric.value();
        j = {{"name", std::string(m.service_name())},
             {"state", static_cast<int>(m.state())},
             {"nominal_hz", m.nominal_rate_hz()},
             {"rate_hz", m.measured_rate_hz()},
             {"tick_cpu_p999_us", static_cast<double>(m.tick_cpu().p999_ns()) * 1e-3},
             {"metrics", std::move(metrics)}};
        break;
      }
      case kGlotticView: {
        msg::GlotticView m;
        if (!common::decode_cdr<msg::GlotticViewPubSubType>(slot.bytes, m)) break;
        j = {{"tool", m.tool_body_id()},    {"percent", m.visible_percent()},
             {"eye", vec(m.eye_m())},       {"target", vec(m.opening_centre_m())},
             {"force_n", m.tool_force_n()}, {"peak_force_n", m.peak_tool_force_n()},
             {"fem_step", m.fem_step()}};
        break;
      }
      default:
        break;
    }
    if (!j.is_null()) {
      scrub(j);
      pieces_[i] = {slot.topic, j.dump()};
    }
  }
  if (state_dirty_) build_state(mode);
}

void PageModel::build_state(const std::string& mode) {
  state_dirty_ = false;
  // The pieces are JSON already: the state frame is assembled from them,
  // one array per topic ("device", "command", "contacts", "services",
  // "glottic").
  static constexpr const char* kNames[kTopicCount] = {"device", "command",  "contacts", nullptr,
                                                      nullptr,  "services", "glottic"};
  std::string s = "{\"op\":\"state\",\"mode\":\"" + mode + "\"";
  for (std::size_t topic = 0; topic < kTopicCount; ++topic) {
    if (kNames[topic] == nullptr) continue;
    s += ",\"";
    s += kNames[topic];
    s += "\":[";
    bool first = true;
    for (const auto& [slot, piece] : pieces_) {
      if (piece.first != topic) continue;
      if (!first) s += ',';
      first = false;
      s += piece.second;
    }
    s += ']';
  }
  char strain[64];
  std::snprintf(strain, sizeof(strain), ",\"max_strain\":%.6g}", max_node_strain_);
  s += strain;
  make(kStateStream, false, false, std::move(s));
}

}  // namespace fahr::visualizer_service
