#!/usr/bin/env bash
# Writes to stdout the scene SCENE with its rigid body 'epiglottis' made a
# deformable one: the generator's tet mesh of the same leaf
# (meshes/neonatal/epiglottis.node), fixed at its base
# (epiglottis_fixed_nodes.txt), with an elastic-cartilage material whose
# modulus is an estimate (docs/design/two-deformable-bodies.md). Its id stays
# 26. Mesh paths become absolute, so the file may live anywhere.
#
#   soft_epiglottis_scene.sh SCENE > OUT.yaml
set -euo pipefail
scene="${1:?usage: soft_epiglottis_scene.sh SCENE}"
dir=$(cd "$(dirname "$scene")" && pwd)
awk -v dir="$dir/" '
  /^ *(mesh|nodes_file): / && $2 !~ /^\// { sub(/: /, ": " dir) }
  /^  - name: / { in_leaf = ($0 == "  - name: epiglottis") }
  in_leaf && /^    mesh: / {
    mesh = $2; sub(/\.obj$/, ".node", mesh)
    fixed = mesh; sub(/\.node$/, "_fixed_nodes.txt", fixed)
    print "    role: deformable"
    print "    mesh: " mesh
    print "    unit: mm"
    print "    material:"
    print "      youngs_modulus_pa: 1.0e6"
    print "      poisson_ratio: 0.45"
    print "      density_kg_per_m3: 1100"
    print "      rayleigh_mass_per_s: 0.1"
    print "      rayleigh_stiffness_s: 0.01"
    print "      model: stable_neo_hookean"
    print "    fixed:"
    print "      nodes_file: " fixed
    print "    aist:"
    print "      sphere_tet_volume_ratio: 10"
    print "      refinement_levels: 1"
    print "      surface_spheres: true"
    print "      sphere_budget: 16384"
    done = 1
    next
  }
  in_leaf && /^    (role|unit|sdf_cell_m): / { next }
  { print }
  END { if (!done) exit 3 }
' "$scene" || { echo "soft_epiglottis_scene: no body 'epiglottis' with a mesh in $scene" >&2; exit 1; }
