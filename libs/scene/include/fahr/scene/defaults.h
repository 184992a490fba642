// Every default of the scene format, in one place. A scene file that omits a
// key gets the value here (the struct members are initialised from these);
// deployment/scenes/format.md documents the same values for users.
#pragma once

#include <chrono>
#include <cstdint>

namespace fahr::scene {

// --- Material: neonatal tongue tissue (linear elastic, isotropic). ---------
// No published stiffness of neonatal tongue was found; adult in-vivo MR
// elastography gives a storage shear modulus of about 2.7 kPa (E = 2 G (1 + nu)
// ~ 8 kPa), ultrasound shear-wave studies of head and neck muscle ~10 kPa.
// Sources: deployment/scenes/format.md, "Material values".
inline constexpr double kDefaultYoungsModulusPa = 10.0e3;
// Tissue is nearly incompressible; 0.45 rather than 0.49 because linear tets
// lock (grow artificially stiff) as nu approaches 0.5.
inline constexpr double kDefaultPoissonRatio = 0.45;
// Soft tissue and skeletal muscle: 1,040-1,060 kg/m^3.
inline constexpr double kDefaultDensityKgPerM3 = 1040.0;
// Rayleigh damping C = alpha M + beta K. Simulation choices, not measurements:
// beta = 10 ms gives a damping ratio of ~0.3 at 10 Hz, where the tongue's
// lowest modes lie; alpha is small so slow, rigid-like motion is not braked.
inline constexpr double kDefaultRayleighMassPerS = 0.1;
inline constexpr double kDefaultRayleighStiffnessS = 0.01;
// Compression stiffening, the Yeoh ratio C20/C10 (libs/fem
// compression_stiffening.h): 0 is the linear corotational material. Off by
// default so a scene without the key behaves as before the key existed.
inline constexpr double kDefaultYeohC20OverC10 = 0.0;

// --- AIST (adaptive inner sphere tree) of a deformable body. ----------------
// The paper finds about 10x the mean tet volume per coarse sphere best.
inline constexpr double kDefaultSphereTetVolumeRatio = 10.0;
inline constexpr int kDefaultRefinementLevels = 2;
inline constexpr bool kDefaultSurfaceSpheres = true;
// The SceneDescription topic carries at most 65,536 spheres (idl MAX_SPHERES).
inline constexpr int kMaxSpheres = 65536;
inline constexpr int kDefaultSphereBudget = 16384;

// --- Rigid bodies. ----------------------------------------------------------
// Signed distance field grid cell: 0.5 mm resolves a blade ~1.5 mm thick.
inline constexpr double kDefaultSdfCellM = 0.5e-3;

// --- Rates. -----------------------------------------------------------------
inline constexpr double kDefaultHapticHz = 1000.0;  // Touch X servo loop
inline constexpr double kDefaultFemHz = 200.0;
inline constexpr double kDefaultStatusHz = 10.0;

// --- Run. -------------------------------------------------------------------
// Lockstep: the haptic tick reads the FEM state this many FEM periods old,
// so a run does not depend on which service finishes a step first.
inline constexpr int kDefaultFemStateDelaySteps = 1;
inline constexpr bool kDefaultSpinWait = false;  // starves 2-core machines

// --- DDS. -------------------------------------------------------------------
inline constexpr int kDefaultDomainId = 0;
// The transport accepts domains 0-230: the RTPS default port mapping
// overflows 16-bit ports past 232 and Cyclone DDS refuses above 230
// (fahr/common/transport_config.h, kMaxDomainId).
inline constexpr int kMaxDomainId = 230;

// --- Gravity: world frame, m/s^2. The neonatal scene overrides it (supine).
inline constexpr double kDefaultGravityX = 0.0;
inline constexpr double kDefaultGravityY = -9.81;
inline constexpr double kDefaultGravityZ = 0.0;

// --- FEM solver. ------------------------------------------------------------
inline constexpr double kDefaultCgTolerance = 1.0e-6;  // relative residual
inline constexpr int kDefaultCgMaxIterations = 200;
inline constexpr int kDefaultProjectionMaxIterations = 20;
// 1 micrometre: two orders below the 0.2 mm depth accuracy asked of contacts.
inline constexpr double kDefaultProjectionToleranceM = 1.0e-6;
inline constexpr int kDefaultMaxCandidateContacts = 96;
// A ContactSet computed on a FEM state older than this is ignored. The FEM
// service measures the age in its own steps: 20 ms is 4 steps at 200 Hz,
// room for a haptic service that takes a few ms to digest a new state (5 ms
// made a third of the sets stale in the end-to-end run) while a set whose
// planes lag the tool by more is dropped.
inline constexpr std::chrono::milliseconds kDefaultMaxContactAge{20};
// Below this node speed, untouched, a body sleeps (no solve).
inline constexpr double kDefaultSleepSpeedMps = 1.0e-4;

// --- Contact and haptic coupling. -------------------------------------------
// Well below the stiffness Touch-class devices are specified to render (of the
// order of 1 N/mm; the device service holds the sourced figures), and
// the haptic service also caps it at the max_stiffness each DevicePose carries.
inline constexpr double kDefaultCouplingStiffnessNPerM = 400.0;
inline constexpr double kDefaultCouplingDampingNsPerM = 1.0;
// Tool constraints freeze when the reaction exceeds the renderable force and
// re-activate below (1 - hysteresis) of it, so the decision does not chatter.
inline constexpr double kDefaultForceAwareHysteresis = 0.1;
inline constexpr double kDefaultPenaltyStiffnessNPerM = 1000.0;
// Deformable/obstacle pairs are tested when their boxes come this close.
inline constexpr double kDefaultDeformableObstacleMarginM = 5.0e-3;

// --- Device. ----------------------------------------------------------------
inline constexpr double kDefaultMotionScale = 1.0;

// --- The whole scene file rides in SceneDescription (idl MAX_SCENE_TEXT).
inline constexpr std::size_t kMaxSceneTextBytes = 65536;

inline constexpr int kSceneFormatVersion = 1;

}  // namespace fahr::scene
