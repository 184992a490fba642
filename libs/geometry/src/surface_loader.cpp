// Surface loading through assimp; fahr welds positions itself as well, since
// assimp joins vertices only when every attribute (normal, uv) matches.
#include "fahr/geometry/surface_loader.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "fahr/geometry/load_error.h"

namespace fahr::geometry {
namespace {

// Exact-position weld: vertices at bit-identical positions become one.
class Welder {
 public:
  Index add(const Eigen::Vector3d& x) {
    const auto key = std::make_tuple(x.x(), x.y(), x.z());
    const auto [it, inserted] = index_.emplace(key, static_cast<Index>(vertices_.size()));
    if (inserted) {
      vertices_.push_back(x);
    }
    return it->second;
  }
  std::vector<Eigen::Vector3d> take() { return std::move(vertices_); }

 private:
  std::map<std::tuple<double, double, double>, Index> index_;
  std::vector<Eigen::Vector3d> vertices_;
};

}  // namespace

SurfaceMesh load_surface(const std::filesystem::path& path, double scale_to_m) {
  const std::string name = path.string();
  if (!(scale_to_m > 0.0) || !std::isfinite(scale_to_m)) {
    throw LoadError(name, 0, "scale to metres must be finite and > 0");
  }
  if (!std::filesystem::exists(path)) {
    throw LoadError(name, 0, "cannot open file");
  }
  Assimp::Importer importer;
  // Drop normals, uvs and colours first, so JoinIdenticalVertices joins by position.
  importer.SetPropertyInteger(
      AI_CONFIG_PP_RVC_FLAGS,
      aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS | aiComponent_COLORS |
          aiComponent_TEXCOORDS | aiComponent_BONEWEIGHTS | aiComponent_ANIMATIONS |
          aiComponent_TEXTURES | aiComponent_LIGHTS | aiComponent_CAMERAS | aiComponent_MATERIALS);
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const unsigned flags = aiProcess_RemoveComponent | aiProcess_Triangulate |
                         aiProcess_JoinIdenticalVertices | aiProcess_SortByPType |
                         aiProcess_PreTransformVertices;
  const aiScene* scene = importer.ReadFile(name, flags);
  if (scene == nullptr) {
    throw LoadError(name, 0,
                    std::string("assimp cannot read the file: ") + importer.GetErrorString());
  }
  Welder welder;
  std::vector<Triangle> triangles;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    std::vector<Index> remap(mesh->mNumVertices);
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      const aiVector3D& p = mesh->mVertices[v];
      const Eigen::Vector3d x = scale_to_m * Eigen::Vector3d(p.x, p.y, p.z);
      if (!x.allFinite()) {
        throw LoadError(name, 0,
                        "mesh " + std::to_string(m) + ", vertex " + std::to_string(v) +
                            ": non-finite coordinate");
      }
      remap[v] = welder.add(x);
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) {
        continue;  // points and lines left by SortByPType
      }
      const Triangle t = {remap[face.mIndices[0]], remap[face.mIndices[1]],
                          remap[face.mIndices[2]]};
      if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
        continue;  // collapsed by the weld: no area, no orientation
      }
      triangles.push_back(t);
    }
  }
  if (triangles.empty()) {
    throw LoadError(name, 0, "no triangles in the file");
  }
  return SurfaceMesh(welder.take(), std::move(triangles));
}

}  // namespace fahr::geometry
