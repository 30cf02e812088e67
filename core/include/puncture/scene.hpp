// scene.hpp: the one description of the tissue, needle and insertion that both
// the real-time model (core/) and the FEM reference (reference_fem/) are built
// from. Plain data only; loading from JSON lives in scene_io.hpp.
//
// Units: everything in these structs is SI (m, N, s, Pa, kg). Scene files use
// mm where the key says so (`*_mm`); the loader converts once.
//
// Geometry convention (shared by every model):
//   * The tissue sample is a cylinder of diameter `sample.diameter_m` whose
//     axis is the z axis. The skin's top surface is the plane z = 0; the
//     layers are stacked downward (skin, fat, muscle, ...) so the tissue
//     occupies -total_thickness <= z <= 0. The base z = -total_thickness is
//     fixed.
//   * The needle moves along -z on the sample axis (x = y = 0). "Depth" is the
//     distance of the needle tip below the undeformed skin surface, positive
//     into the tissue: depth_m = -z_tip.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace puncture {

/// Parameters of one layer's mass-spring force mesh (seed paper Fig. 1-2,
/// Eq. 5, Table 2).
struct ForceMeshParams {
  double virtual_stiffness_N_per_m = 160.0;  ///< K: virtual spring per node, along the normal
  int rings_w = 8;                           ///< w: number of concentric hexagonal rings (ring 1 = contact node)
  double spacing_L_m = 2e-3;                 ///< L: rest length of the surface springs
  double surface_stiffness_N_per_m = 200.0;  ///< k_s: out-of-plane (membrane) stiffness of one surface spring
  double deformed_threshold_m = 0.01e-3;     ///< a ring counts as deformed when its mean deflection exceeds this
  double node_damping_N_s_per_m = 0.05;      ///< viscous damping of each node (dynamics of the mesh)
};

/// Continuum material of one layer for the FEM reference.
struct ContinuumMaterial {
  std::string model = "neo_hookean";  ///< "neo_hookean" or "mooney_rivlin"
  double youngs_modulus_Pa = 1e5;
  double poisson_ratio = 0.45;
  double mooney_rivlin_c01_fraction = 0.0;  ///< share of the shear modulus carried by the C01 (I2) term
  std::string source;                       ///< where the numbers come from
};

/// When the FEM reference counts a layer as punctured.
struct PunctureCriterion {
  enum class Kind { CriticalForce, CriticalStretch };
  Kind kind = Kind::CriticalForce;
  double critical_force_N = 1.0;     ///< needle force at which the layer breaks
  double critical_stretch = 1.5;     ///< maximum principal stretch at the tip at which it breaks
};

struct Layer {
  std::string name;
  double thickness_m = 1e-3;
  double density_kg_per_m3 = 1050.0;
  ForceMeshParams force_mesh;
  /// d: damping per unit inserted needle length, N s / m^2 (Table 1 reads
  /// F = d h v; see core/README.md for why this unit).
  double damping_N_s_per_m2 = 3000.0;
  double resumption_rate = 0.05;  ///< eta_r of Eq. (8): drop of the recovery factor per haptic step
  ContinuumMaterial material;
  PunctureCriterion puncture;
};

struct Sample {
  double diameter_m = 0.06;  ///< lateral size: diameter of the cylindrical tissue sample
};

struct Needle {
  double radius_m = 0.635e-3;  ///< outer radius (18 G = 1.27 mm outer diameter)
  std::string tip = "blunt";   ///< "blunt" (flat cylinder end); the only tip shape modelled so far
};

/// Scripted straight insertion: approach from start_height above the skin,
/// insert to target_depth at constant speed, dwell, withdraw to the start.
struct Insertion {
  double start_height_m = 2e-3;          ///< tip height above the skin surface at t = 0
  double speed_m_per_s = 0.01;           ///< insertion speed (>= 0)
  double target_depth_m = 0.03;          ///< deepest tip depth below the skin surface
  double dwell_s = 0.5;                  ///< pause at the target depth
  double withdrawal_speed_m_per_s = 0.01;///< withdrawal speed (> 0), back to the start height
  double angle_deg = 0.0;                ///< angle between needle and surface normal; only 0 is supported
};

/// Settings of the real-time model.
struct RealtimeSettings {
  int sh_degree = 16;                     ///< l: maximum degree of the SH surfaces
  double haptic_rate_Hz = 1000.0;         ///< tick rate of the haptic loop
  std::string integrator = "implicit";    ///< "explicit", "implicit" or "quasi_static" (force mesh dynamics)
  double frame_rate_Hz = 30.0;            ///< rate of the surface frames written for visualisation
};

/// Settings of the FEM reference.
struct FemSettings {
  int refinement = 0;             ///< global refinements of the base mesh
  int element_degree = 1;         ///< 1 (Q1) or 2 (Q2)
  double load_step_m = 0.25e-3;   ///< needle travel per quasi-static load step
  int max_newton_iterations = 25;
  double newton_tolerance = 1e-8;
};

/// Effects a scene can switch on. An effect that is off is not constructed.
struct Effects {
  bool surface_force = true;   ///< force-mesh surface force before a layer breaks (Table 1, F_s/F_f/F_m)
  bool damping = true;         ///< puncture damping force d h v inside punctured layers (Table 1)
  bool resumption = true;      ///< shape-matching surface resumption after breakthrough (Eq. 6-8)
  bool surface_output = true;  ///< deformed layer surfaces written as VTK frames
};

/// Tetrahedral mesh of the slab for the comparison models (meshing/tet):
/// the target edge length grows from size_at_axis at the needle radius by
/// `grading` per unit radial distance, up to size_far.
struct ComparisonMeshSettings {
  double size_at_axis_m = 1.0e-3;  ///< tetrahedron size at the needle
  double size_far_m = 8e-3;        ///< largest tetrahedron size, far from the axis
  double grading = 0.5;            ///< growth of the size per metre of distance from the needle radius
};

/// Settings of the comparison models of `puncture compare` (core/comparison):
/// volumetric mass-spring, tensor-mass (linear, StVK, visco-elastic), BEM, SHF.
struct ComparisonSettings {
  ComparisonMeshSettings mesh;
  /// Time integration of the volumetric models through SUNDIALS: "implicit"
  /// (CVODE BDF, Newton-Krylov) or "explicit" (ARKODE explicit Runge-Kutta).
  std::string integrator = "implicit";
  double relative_tolerance = 1e-4;       ///< integrator relative tolerance
  double absolute_tolerance_m = 1e-7;     ///< integrator absolute tolerance on positions (velocities: per second)
  double mass_damping_per_s = 20.0;       ///< alpha of the Rayleigh damping Y = alpha M + beta K0 (seed 001: M x'' = -K x - Y x')
  double stiffness_damping_s = 1e-3;      ///< beta: stiffness-proportional part (K0 = tangent at rest); damps the mesh's high modes
  std::vector<double> prony_g{0.5};       ///< visco-elastic tensor-mass: Prony moduli g_k (relative to the long-term modulus)
  std::vector<double> prony_tau_s{0.5};   ///< and relaxation times tau_k
  /// Per layer factor on the mass-spring stiffnesses (empty: all 1); set by
  /// the parameter identification against the FEM.
  std::vector<double> mass_spring_stiffness_scale;
};

struct Scene {
  std::string name;
  std::string description;
  std::string source_path;   ///< file the scene was loaded from (for messages)
  Sample sample;
  std::vector<Layer> layers;  ///< top (skin) to bottom
  Needle needle;
  Insertion insertion;
  RealtimeSettings realtime;
  FemSettings fem;
  std::vector<std::string> models{"realtime"};  ///< which models a run uses: "realtime", "fem"
  Effects effects;
  ComparisonSettings comparison;

  double total_thickness_m() const {
    double t = 0.0;
    for (const auto& l : layers) t += l.thickness_m;
    return t;
  }
  /// Depth of the top surface of layer i below the skin surface (0 for the skin).
  double layer_top_depth_m(std::size_t i) const {
    double t = 0.0;
    for (std::size_t k = 0; k < i && k < layers.size(); ++k) t += layers[k].thickness_m;
    return t;
  }
};

}  // namespace puncture
