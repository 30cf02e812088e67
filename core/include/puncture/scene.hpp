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
  /// k_a: in-plane (stretch) stiffness of one surface spring. A spring of rest
  /// length L whose ends differ in deflection by delta is stretched to
  /// sqrt(L^2 + delta^2): its transverse force gains k_a (s - L) delta / s, so
  /// the mesh stiffens with its own slope (force_mesh.hpp). 0: linear springs.
  double surface_axial_stiffness_N_per_m = 0.0;
  /// z_v: the virtual springs stiffen with their own deflection,
  /// f = K z (1 + (z / z_v)^2) (the tissue under the surface compressed). 0: linear.
  double virtual_stiffening_m = 0.0;
  bool nonlinear() const { return surface_axial_stiffness_N_per_m > 0.0 || virtual_stiffening_m > 0.0; }
};

/// One term of an Ogden law: its share of the initial shear modulus and its
/// exponent (see ContinuumMaterial).
struct OgdenTerm {
  double mu_fraction = 1.0;  ///< mu_p / mu_0 (the shares of all terms sum to 1)
  double alpha = 2.0;        ///< alpha_p (nonzero; alpha = 2 is neo-Hookean)
};

/// Continuum material of one layer for the FEM reference. Every law is
/// isochoric + volumetric (reference_fem/include/puncture/fem/hyperelastic_materials.hpp);
/// E and nu are the SMALL-STRAIN (initial) values: they fix the initial shear
/// modulus mu_0 = E / (2 (1 + nu)) and the bulk modulus kappa = E / (3 (1 - 2 nu)),
/// whatever the law does at large strain. For a viscoelastic layer they are
/// the instantaneous or the long-term values (Viscoelasticity::modulus_basis).
///   neo_hookean:      mu_0/2 (I1bar - 3)
///   mooney_rivlin:    c10 (I1bar - 3) + c01 (I2bar - 3), c01 = fraction x mu_0 / 2
///   ogden:            sum_p 2 mu_p / alpha_p^2 (lambda1bar^alpha_p + lambda2bar^alpha_p + lambda3bar^alpha_p - 3),
///                     mu_p = mu_fraction_p x mu_0 (strain-stiffening for alpha > 2)
///   veronda_westmann: c1 (exp(gamma (I1bar - 3)) - 1) - c1 gamma / 2 (I2bar - 3), c1 = mu_0 / gamma
///                     (exponential stiffening; Veronda & Westmann 1970)
/// One term of a normalised Prony series (relaxation function)
///   g(t) = 1 - sum_i g_i (1 - exp(-t / tau_i)),
/// the form in which stress-relaxation tests are reported (Abaqus, FEBio).
struct PronyRelaxationTerm {
  double g = 0.0;      ///< g_i in (0, 1): share of the instantaneous modulus that relaxes with tau_i
  double tau_s = 1.0;  ///< tau_i > 0, s
};

/// Viscoelasticity of a layer's isochoric (shear) response in the FEM
/// reference: a finite-strain Prony series (Simo 1987; Holzapfel 2000,
/// Sec. 6.10; reference_fem/include/puncture/fem/viscoelastic_material.hpp).
/// The bulk response stays elastic. No terms: the layer is elastic.
struct Viscoelasticity {
  std::vector<PronyRelaxationTerm> terms;
  /// Which modulus the layer's youngs_modulus_Pa (and its Ogden/... law) is:
  ///   instantaneous: measured fast (at t = 0+); the long-term law is that law
  ///     scaled by the relaxed fraction g_inf = 1 - sum g_i;
  ///   long_term: measured at equilibrium; the instantaneous law is 1 / g_inf
  ///     times stiffer.
  enum class ModulusBasis { Instantaneous, LongTerm };
  ModulusBasis modulus_basis = ModulusBasis::Instantaneous;
  std::string source;  ///< where the terms come from

  bool enabled() const { return !terms.empty(); }
  /// g_inf = 1 - sum g_i: the fraction of an instantaneous stress left after full relaxation.
  double relaxed_fraction() const {
    double g_inf = 1.0;
    for (const PronyRelaxationTerm& t : terms) g_inf -= t.g;
    return g_inf;
  }
};

struct ContinuumMaterial {
  std::string model = "neo_hookean";  ///< "neo_hookean", "mooney_rivlin", "ogden" or "veronda_westmann"
  double youngs_modulus_Pa = 1e5;     ///< initial (small-strain) Young's modulus
  double poisson_ratio = 0.45;        ///< initial Poisson's ratio (sets the bulk modulus)
  double mooney_rivlin_c01_fraction = 0.0;  ///< share of the shear modulus carried by the C01 (I2) term
  std::vector<OgdenTerm> ogden_terms;       ///< model "ogden": at least one term
  double veronda_westmann_gamma = 1.0;      ///< model "veronda_westmann": exponent gamma (> 0)
  Viscoelasticity viscoelastic;             ///< Prony relaxation of the isochoric part (none: elastic)
  std::string source;                       ///< where the numbers come from
};

/// When the FEM reference counts a layer as punctured.
///   fracture_energy: a cohesive crack along the needle path (bilinear
///     traction-separation law with strength sigma_c and toughness G_c = area
///     under the law) opens ahead of the needle's cutting edge; the layer
///     breaks when its crack opens, and the crack advances with the tip
///     (reference_fem/README.md). Mesh-independent once the mesh resolves the
///     cohesive zone.
///   critical_force / critical_stretch: the older criteria (needle force, or
///     maximum principal stretch at the tip); the layer's crack opens at once.
struct PunctureCriterion {
  enum class Kind { CriticalForce, CriticalStretch, FractureEnergy };
  Kind kind = Kind::CriticalForce;
  double critical_force_N = 1.0;     ///< needle force at which the layer breaks
  double critical_stretch = 1.5;     ///< maximum principal stretch at the tip at which it breaks
  double toughness_J_per_m2 = 1000.0;    ///< G_c: fracture energy per unit crack area
  double cohesive_strength_Pa = 1e6;     ///< sigma_c: peak traction of the cohesive law
  std::string source;                    ///< where G_c and sigma_c come from
};

/// Friction between the needle shaft and the tissue of one layer in the FEM
/// reference (Coulomb with a static and a dynamic coefficient, Karnopp-like
/// stick-slip; regularised by a tangential penalty). 0 = frictionless.
struct ShaftFriction {
  double dynamic_coefficient = 0.0;  ///< mu_d: sliding friction coefficient (>= 0)
  double static_coefficient = 0.0;   ///< mu_s >= mu_d: limit to break a sticking contact
  std::string source;
};

/// Real-time force law of one layer beyond the paper's Table 1 (each part is
/// used only when its effect is on, see Effects). core/README.md "Force law"
/// gives the equations; scenes/README.md the keys of the layer's `force_law`
/// object.
struct StiffeningLaw {
  /// Extra force of the virtual spring under the needle tip (the contact
  /// node), on top of its linear K z:
  ///   Polynomial:  a2 z^2 + a3 z^3            (with a linear mesh: F = S z + a2 z^2 + a3 z^3)
  ///   Exponential: k_e z_s (exp(z / z_s) - 1 - z / z_s)
  enum class Kind { Polynomial, Exponential };
  Kind kind = Kind::Polynomial;
  double quadratic_N_per_m2 = 0.0;      ///< a2 (>= 0)
  double cubic_N_per_m3 = 0.0;          ///< a3 (>= 0)
  double exponential_stiffness_N_per_m = 0.0;  ///< k_e (>= 0): stiffness scale of the exponential law
  double strain_scale_m = 1e-3;         ///< z_s (> 0): deflection over which the exponential law stiffens by e
};

/// When the layer the needle presses breaks (the real-time model's criterion;
/// the FEM has its own, PunctureCriterion).
struct BreakthroughCriterion {
  /// Rings: the paper's rule (ring w deformed beyond ForceMeshParams::deformed_threshold_m);
  /// CriticalForce: the layer's surface force reaches critical_force_N;
  /// CriticalEnergy: the elastic energy stored in the layer's force mesh reaches critical_energy_J.
  enum class Kind { Rings, CriticalForce, CriticalEnergy };
  Kind kind = Kind::Rings;
  double critical_force_N = 1.0;   ///< at reference_speed_m_per_s
  double critical_energy_J = 1e-3; ///< at reference_speed_m_per_s
  /// n (0 .. 1): the critical force or energy grows with the layer's mean
  /// pressing speed v as (v / v_ref)^n (a viscoelastic solid's apparent
  /// fracture toughness rises with the loading rate; breakthrough_rate.hpp).
  /// 0: rate-independent (the paper). Not used by the ring rule.
  double rate_exponent = 0.0;
  double reference_speed_m_per_s = 0.01;  ///< v_ref (> 0): the speed the critical values hold at
};

/// Karnopp shaft friction per unit length of shaft inside a punctured layer
/// (the viscous part is the paper's d h v, Layer::damping_N_s_per_m2).
struct ShaftFrictionLaw {
  double static_N_per_m = 0.0;          ///< f_s: largest friction per metre of shaft while the shaft sticks
  double dynamic_N_per_m = 0.0;         ///< f_d: friction per metre of shaft while it slides (<= f_s)
  double velocity_band_m_per_s = 1e-4;  ///< Karnopp's band: |v| below it counts as sticking
  /// delta (>= 0): shaft travel over which the friction builds up and reverses
  /// (the tissue around the shaft is dragged along elastically before it
  /// slips: an elastic-plastic "presliding" interface of stiffness f_d / delta
  /// per metre of shaft). 0: Karnopp's instant reversal.
  double presliding_m = 0.0;
  /// The shaft's contact pressure, and with it the friction per metre, relaxes
  /// with the layer's own Prony series (material.viscoelastic) from the moment
  /// the tip passed each point of the shaft (shaft_pressure_relaxation.hpp).
  /// JSON "pressure_relaxation": "layer_material"; false ("none"): it does not.
  bool pressure_relaxes_with_material = false;
};

/// Rate dependence of a layer's cutting force (cutting.hpp):
///     C(v) = C [(1 - b) + b v / v_ref],
/// v the needle's axial speed while the tip cuts (clamped to [0, 100 v_ref]).
/// The part b C v / v_ref is the viscous resistance of the tissue the bevel
/// wedges apart (reported with the tip force); the rest is the fracture
/// energy G_c w. b = 0: a rate-independent cutting force (the default).
struct CuttingRate {
  double viscous_fraction = 0.0;          ///< b in [0, 1]: the viscous part of C at v_ref
  double reference_speed_m_per_s = 0.01;  ///< v_ref (m/s): the speed at which C is the whole cutting force
};

/// Rate dependence of a layer's rupture release length (cutting.hpp):
///     l(v_b) = l (v_b / v_ref)^m,
/// v_b the needle's axial speed at the layer's break, clamped to
/// [v_ref / 100, 100 v_ref]. m = 0: l at every speed (the default).
struct ReleaseRate {
  double exponent = 0.0;                  ///< m in [0, 1]
  double reference_speed_m_per_s = 0.01;  ///< v_ref (m/s): the speed at which the length is l
};

struct ForceLaw {
  BreakthroughCriterion breakthrough;
  StiffeningLaw stiffening;
  double cutting_force_N = 0.0;         ///< C: force to advance the crack through the layer at v_ref (~ G_c x cut width)
  CuttingRate cutting_rate;             ///< C's rate dependence (b = 0: none)
  double cutting_release_m = 0.1e-3;    ///< retraction over which the cutting force falls to 0
  /// l (m, >= 0): tip travel past the break over which the surface force the
  /// layer carried beyond its cutting force is released (exp(-s / l), the
  /// crack's cohesive process zone; cutting.hpp). 0: at once (the paper).
  double rupture_release_m = 0.0;
  ReleaseRate rupture_release_rate;     ///< l's rate dependence (m = 0: none)
  ShaftFrictionLaw friction;
};

struct Layer {
  std::string name;
  double thickness_m = 1e-3;
  double density_kg_per_m3 = 1050.0;
  ForceMeshParams force_mesh;
  /// d: damping per unit inserted needle length, N s / m^2 (Table 1 reads
  /// F = d h v; see core/README.md for why this unit).
  double damping_N_s_per_m2 = 3000.0;
  /// Time (s) in which a broken surface returns to its rest shape (Eq. 8 with
  /// eta falling linearly in time). What the simulator uses: independent of the
  /// haptic rate. A scene file giving only the paper's eta_r
  /// (`resumption_rate`, the drop of the recovery factor per haptic step) sets
  /// it to 1 / (eta_r x haptic rate of that file) when it is read.
  double resumption_time_s = 0.02;
  ForceLaw force_law;
  ContinuumMaterial material;
  PunctureCriterion puncture;
  ShaftFriction shaft_friction;  ///< FEM reference: needle shaft - tissue friction
};

struct Sample {
  double diameter_m = 0.06;  ///< lateral size: diameter of the cylindrical tissue sample
};

/// The needle. The real-time model uses the outer radius; the FEM reference
/// also models the tip (reference_fem/README.md):
///   "blunt":  a solid flat-ended cylinder (flat punch);
///   "bevel":  a cutting tip; the FEM (axisymmetric) idealises the planar
///             crack of width 2a that a bevel opens by a ring crack with the
///             same face perimeter (radius 2a/pi) whose fracture energy per
///             unit depth equals G_c x 2a, and a conical flank of
///             tip_angle_deg that spreads the crack open to the shaft radius;
///   "hollow": a coring needle: the lumen edge (inner_radius) cuts a ring
///             crack, the wall's conical flank spreads the tissue to the shaft.
struct Needle {
  double radius_m = 0.635e-3;  ///< outer radius a (18 G = 1.27 mm outer diameter)
  std::string tip = "blunt";   ///< "blunt", "bevel" or "hollow"
  double inner_radius_m = 0.419e-3;  ///< "hollow": lumen radius (18 G thin wall: 0.838 mm inner diameter)
  double tip_angle_deg = 20.0;       ///< "bevel"/"hollow": angle between the tip flank and the needle axis
};

/// Scripted straight insertion: approach from start_height above the skin,
/// insert to target_depth at constant speed, dwell, withdraw to the start.
struct Insertion {
  double start_height_m = 2e-3;          ///< tip height above the skin surface at t = 0
  double speed_m_per_s = 0.01;           ///< insertion speed (>= 0)
  double target_depth_m = 0.03;          ///< deepest tip depth below the skin surface
  double dwell_s = 0.5;                  ///< pause at the target depth
  double withdrawal_speed_m_per_s = 0.01;///< withdrawal speed (> 0), back to the start height
  double angle_deg = 0.0;                ///< angle between needle and surface normal (deg; needle.hpp); the FEM takes 0 only
  double azimuth_deg = 0.0;              ///< direction the needle tilts towards, from +x towards +y (deg, [0, 360); needle.hpp)
};

/// Settings of the real-time model.
struct RealtimeSettings {
  int sh_degree = 16;                     ///< l: maximum degree of the SH surfaces
  double haptic_rate_Hz = 1000.0;         ///< tick rate of the haptic loop
  std::string integrator = "implicit";    ///< "explicit", "implicit" or "quasi_static" (force mesh dynamics)
  double frame_rate_Hz = 30.0;            ///< rate of the surface frames written for visualisation
};

/// Resolution of the FEM reference's mesh (meshing/). Element sizes follow
/// the needle radius and each layer's thickness, so a scene cannot silently
/// get a mesh too coarse to trust (reference_fem/README.md, "Mesh").
struct FemMeshSettings {
  int elements_per_needle_radius = 8;  ///< radial elements across the needle radius a (under the tip)
  int min_elements_per_layer = 6;      ///< at least this many elements through every layer
  double radial_growth = 1.25;         ///< geometric growth of the element size away from the needle
  double path_element_size_mm = 0.25; ///< largest element height along the needle path
};

/// Settings of the FEM reference.
struct FemSettings {
  /// "axisymmetric" (meridian plane: the cutting needle, fracture-energy
  /// puncture, friction, the whole trajectory), "3d" (flat punch, older
  /// criteria, insertion only) or "auto": axisymmetric for a cutting tip
  /// (bevel, hollow), 3d for a blunt one.
  std::string geometry = "auto";
  int refinement = 0;             ///< global refinements of the base mesh
  int element_degree = 1;         ///< 1 (Q1) or 2 (Q2)
  double load_step_m = 0.25e-3;   ///< needle travel per quasi-static load step
  int max_newton_iterations = 25;
  double newton_tolerance = 1e-8;
  FemMeshSettings mesh;
  /// Viscous regularisation time of the cohesive damage (s): damage follows
  /// its rate-independent value with this delay, so that an unstable crack
  /// jump is traced over a few steps instead of defeating Newton.
  double cohesive_viscosity_s = 2e-3;
  /// Axisymmetric FEM: Kelvin-Voigt stabilisation time (s) on each step's
  /// strain increment, which carries the solution through snaps (0: off).
  double stabilization_time_s = 1e-3;
};

/// Effects a scene can switch on. An effect that is off is not constructed.
struct Effects {
  bool surface_force = true;   ///< force-mesh surface force before a layer breaks (Table 1, F_s/F_f/F_m)
  bool damping = true;         ///< puncture damping force d h v inside punctured layers (Table 1)
  bool resumption = true;      ///< shape-matching surface resumption after breakthrough (Eq. 6-8)
  bool surface_output = true;  ///< deformed layer surfaces written as VTK frames
  // Force-law effects beyond Table 1 (off unless a scene lists them; see ForceLaw).
  bool cutting = false;            ///< cutting force while the tip advances the crack in a punctured layer
  bool friction = false;           ///< Karnopp shaft friction per punctured layer (Coulomb part; d h v is `damping`)
  bool stiffening = false;         ///< strain-stiffening virtual spring under the tip
  bool layer_interaction = false;  ///< layers in series: a layer pressed by the one above carries the load in its own force mesh
  bool coupled_surfaces = false;   ///< surfaces drawn as one deformed slab (coupled_surfaces.hpp); changes no force
};

/// What the haptic device may be sent (the real-time app's stability guard,
/// apps/realtime_app). Defaults: the Geomagic Touch (PHANTOM Omni) data
/// sheet (3.3 N peak force, 1.02 N/mm stiffness along its weakest axis);
/// device damping b = 0.51 N s/m is the value at which that stiffness is
/// passive at 1 kHz by K T / 2 <= b (Colgate and Brown 1994), an inferred
/// value: measure your device.
struct Haptics {
  double max_force_N = 3.3;                      ///< magnitude limit of the force sent to the device
  double max_force_rate_N_per_s = 1000.0;        ///< limit on the change of that force per second
  double device_damping_N_s_per_m = 0.51;        ///< b: physical damping of the device
  double device_max_stiffness_N_per_m = 1020.0;  ///< largest stiffness the device renders (data sheet)
};

/// Tetrahedral mesh of the slab for the comparison models (meshing/):
/// the target edge length grows from size_at_axis at the needle radius by
/// `grading` per unit radial distance, up to size_far.
struct ComparisonMeshSettings {
  /// "extruded": plan triangulation extruded through the layers
  /// (extruded_tet_slab_mesh.hpp); "delaunay": CGAL Mesh_3 (tet_slab_mesh.hpp).
  std::string kind = "extruded";
  double size_at_axis_m = 1.0e-3;  ///< tetrahedron size at the needle
  double size_far_m = 8e-3;        ///< largest tetrahedron size, far from the axis
  double grading = 0.5;            ///< growth of the size per metre of distance from the needle radius
};

/// Settings of the comparison models of `puncture compare` (core/models):
/// volumetric mass-spring, tensor-mass (linear, StVK, visco-elastic), BEM, SHF.
struct ComparisonSettings {
  ComparisonMeshSettings mesh;
  /// Time integration of the volumetric models through SUNDIALS: "implicit"
  /// (CVODE BDF, Newton-Krylov) or "explicit" (ARKODE explicit Runge-Kutta).
  std::string integrator = "implicit";
  /// Volumetric mass-spring model's springs: "linear" (seed 001's M x'' = -K x - Y x'
  /// with K constant: each spring linearised about its rest direction) or
  /// "nonlinear" (geometrically exact springs).
  std::string mass_spring_springs = "linear";
  double relative_tolerance = 1e-4;       ///< integrator relative tolerance
  double absolute_tolerance_m = 1e-7;     ///< integrator absolute tolerance on positions (velocities: per second)
  double mass_damping_per_s = 20.0;       ///< alpha of the Rayleigh damping Y = alpha M + beta K0 (seed 001: M x'' = -K x - Y x')
  double stiffness_damping_s = 1e-3;      ///< beta: stiffness-proportional part (K0 = tangent at rest); damps the mesh's high modes
  std::vector<double> prony_g{0.5};       ///< visco-elastic tensor-mass: Prony moduli g_k (relative to the long-term modulus)
  std::vector<double> prony_tau_s{0.5};   ///< and relaxation times tau_k
  /// Per layer factor on the mass-spring stiffnesses (empty: all 1); set by
  /// the parameter identification against the FEM.
  std::vector<double> mass_spring_stiffness_scale;
  /// Per layer factor on the Young's modulus every continuum comparison model
  /// (SHF, BEM, mass-spring, tensor-mass) reads (empty: all 1); set by
  /// `puncture compare`'s identification against the FEM.
  std::vector<double> stiffness_scale;
  /// Per layer from the top (fewer entries: the rest by their rules): the
  /// comparison models break layer k when the tip reaches this depth (m),
  /// whatever its rule; replays a reference's punctures (the identification
  /// of `puncture compare` uses it). Empty: every layer by its rule.
  std::vector<double> prescribed_puncture_depths_m;
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
  Effects effects;
  Haptics haptics;  ///< optional "haptics" object of the scene file
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
