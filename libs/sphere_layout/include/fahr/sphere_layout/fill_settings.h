// Settings of the sphere filling of a tet mesh (paper 3.1.1, extended with
// surface-hugging spheres that close the coverage gap of its section 4.3).
// Every length is in metres; every count has a stated range. Validated by
// validate_fill_settings(), whose messages name the field.
#pragma once

#include <cstddef>
#include <limits>

namespace fahr::sphere_layout {

struct FillSettings {
  // Coarse sphere volume over the mean tet volume, in [0.5, 1000]. The paper
  // found about 10 best; the coarse cell is the cube the sphere circumscribes,
  // so neighbouring coarse spheres overlap and leave no gap inside.
  double volume_ratio = 10.0;
  // Octree splits of cells the boundary crosses, in [0, 6]. Each split halves
  // the radius.
  int refinement_levels = 1;
  // Tets a sphere is tied to (the nearest that overlap it), in [1, 64]. The
  // paper: "about ten".
  int max_linked_tets = 10;
  // Share of a grid sphere's weight spread from the tet containing its centre
  // to the other linked tets, in [0, 1). The spread is cut where a node
  // weight would turn negative, so weights stay >= 0. Surface-hugging spheres
  // take hugging_weight_spread instead: they stand for the surface, and a
  // spread centre lags a local indentation (aist_bench trajectory: recall
  // 72.7% with 0.5 on every sphere, 79.6% with 0).
  double weight_spread = 0.5;
  double hugging_weight_spread = 0.0;  // in [0, 1)
  // Surface-hugging spheres tied to the surface (ours): a value k > 1 writes
  // the centre of a hugging sphere 1/k of the way from its tangent point on
  // the boundary to a point k times as deep, so the boundary face's nodes
  // carry 1 - 1/k of its weight and the FEM moves the surface when it
  // projects the sphere. With 1 (the previous rule: the tet holding the
  // centre, spread by hugging_weight_spread) a pressed surface node that no
  // sphere carries stays in the tool while the spheres under it are pushed
  // out (aist_bench trajectory: tongue vertices up to 0.6 mm inside the blade
  // and 1-2 mm from the sphere union). In [1, 8].
  double hugging_anchor_depth_factor = 3.0;
  // Surface anchors (SphereLayout, SurfaceAnchor): a sphere whose surface
  // lies within this of the boundary at rest (|c - p| - r <= anchor_gap_m,
  // p its centre's nearest boundary point) is given p as its anchor; others
  // get none and report their own depth only. m, >= 0, +infinity (the
  // default): every sphere. A sphere deep inside touches a tool only where
  // the surface above it is pressed in, and its nearest boundary face is
  // then usually that surface: on aist_bench detection anchoring every
  // sphere gave a lower depth error than 0.5 mm (the coverage target)
  // or 2 mm (docs/design/aist-layout.md).
  double anchor_gap_m = std::numeric_limits<double>::infinity();
  // false: no sphere gets an anchor, whatever anchor_gap_m says. For a
  // caller that never asks for the surface point (QuerySettings::
  // SurfaceProbe::kNone, the haptic service): anchors would only cost a
  // gather of each anchor face per state in SphereState::update and
  // SphereTree::refit. Sphere ids do not depend on it.
  bool surface_anchors = true;
  // A finest-level sphere clipped to the surface is kept only if its radius
  // is at least this fraction of the level radius, in [0, 1]: smaller ones add
  // nodes to link but hardly any covered volume.
  double min_radius_fraction = 0.25;
  // Surface-hugging spheres (ours, beyond the paper): spheres tangent to the
  // surface from inside, added greedily until every boundary sample lies
  // within hugging_tolerance_m of the sphere union.
  bool surface_hugging = true;
  // Greedy closure target, m, > 0. Half the 0.5 mm coverage target, so the
  // gaps between closure samples stay below the target too.
  double hugging_tolerance_m = 0.25e-3;
  // Spacing of the boundary samples the closure checks, m, > 0.
  double hugging_sample_spacing_m = 0.3e-3;
  // Radius of a hugging sphere as a fraction of the finest level radius, in
  // (0, 4]: larger spheres dip less between neighbours, so fewer are needed,
  // but reach less into thin parts (where the radius is halved up to three
  // times). 2 with one refinement level is the coarse radius: on the neonatal
  // tongue 8.3k spheres for 0.42 mm, against 9.3k for 0.62 mm with 1.
  double hugging_radius_fraction = 2.0;
  // Closure rounds (boundary side, then the sphere-union side), in [0, 8].
  int hugging_rounds = 3;
  // Budget: more spheres than this is refused, >= 1.
  std::size_t max_spheres = 20000;
};

// Throws std::invalid_argument naming the field and its valid range.
void validate_fill_settings(const FillSettings& settings);

}  // namespace fahr::sphere_layout
