// model_identification.hpp: the few free parameters of a comparison model
// identified against the reference (FEM) on the calibration trajectory, on
// the model that is then compared (its full run, not a surrogate): per layer
// a factor s_k on its Young's modulus (ComparisonSettings::stiffness_scale)
// and the critical contact force F_k at which it breaks
// (layer_breakthrough.hpp: the kind of criterion the calibrated real-time
// model uses).
//
// In:  a comparison model's name (model_factory.hpp; not "realtime", which
//      `puncture calibrate` tunes), the scene (its insertion is the
//      calibration trajectory), the comparison mesh (volumetric models; else
//      null), the reference data, and whether to identify the stiffness.
// Method. The reference's puncture depths d_k (reference_events,
// puncture_events.hpp) of the layers it punctures on this trajectory. Every
// run below is a run of the full model along the trajectory until the tip
// first reaches d_k, with layer k never breaking and the layers above it
// broken where the reference breaks them (ComparisonSettings::
// prescribed_puncture_depths_m), so its window does not move with their
// parameters.
//   1. The factors, bottom up (a pressed layer's force depends on the layers
//      below it, whose factors are then known): run A with s_k = 1; over the
//      reference's samples with layer k pressed (its state column's pressed
//      samples before its puncture, the FEM's; without states the pressing
//      segment of layer_segments), the model's
//      contact force c_i and shaft force p_i at the sample's depth (linear in
//      depth between steps) and the reference force f_i (with shaft forces
//      when the reference has them, as the comparison compares totals). The
//      least-squares factor for a contact force proportional to the modulus,
//      sum c_i (f_i - p_i) / sum c_i^2 (within the bounds), starts
//      Levenberg-Marquardt on ln s_k in [-ln 1000, ln 1000] with the
//      residuals (contact force of a run with s_k - (f_i - p_i)) / reference
//      peak (levenberg_marquardt.hpp, the calibration's optimiser; at most 14
//      runs, two at a time). The proportional factor is exact only when the
//      pressed layer's response scales with its own modulus alone (one layer
//      on a rigid base); a layer on other layers needs the iterations.
//   1b. With two or more factors fitted: Levenberg-Marquardt on all of them
//      at once, from the bottom-up values, on all their windows, each
//      evaluation one run to the deepest fitted layer's puncture (the layers
//      above broken where the reference breaks them). A layer's factor also
//      shapes the force while the layers above it are pressed (a volumetric
//      model's skin rests on its fat), which the bottom-up pass cannot weigh;
//      the factors are kept when the joint fit does not lower the cost. It
//      stops after its first run when the windows there cost within 1 % of
//      their own bottom-up fits together (no window moved with the other
//      layers' factors: the BEM's and SHF's never do).
//   2. The critical forces, top down, with the final factors: F_k is the
//      contact force on the step at d_k, so the model, breaking each layer by
//      its critical force, breaks it where the reference does.
//   Without stiffness identification step 1 is skipped (s_k = 1).
// A layer the reference does not puncture, or punctures on the haptic step
// that punctures the layer above (never pressed: no strength to identify),
// ends the identification there before any run, so no factor below it is
// fitted for nothing; so does a layer at whose puncture depth the model's
// force is not positive (step 2). Either way identified = false, with the
// reason, and the layers below keep the scene's values.
// Out: ModelIdentification; with_identified_parameters(scene, id) gives the
// model's scene (stiffness_scale, each identified layer's rule CriticalForce
// F_k). The identified values are model properties: held-out cases (other
// speeds, depths, slabs) run with them unchanged.
#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "puncture/meshing/tet_mesh.hpp"
#include "puncture/scene.hpp"
#include "puncture/validation/model_comparison.hpp"

namespace puncture::validation {

/// The stiffness factors s_k are searched in [1 / kStiffnessScaleBound,
/// kStiffnessScaleBound] (on ln s).
inline constexpr double kStiffnessScaleBound = 1000.0;
/// True when s lies within a factor 1.1 of either bound: the fit was stopped
/// by the bound, or nearly, so the factor absorbs what the model lacks rather
/// than measuring a modulus (the report says so beside it).
bool near_stiffness_scale_bound(double scale);

struct LayerIdentification {
  std::string layer;
  bool identified = false;
  double stiffness_scale = 1.0;
  double critical_force_N = 0.0;
  double reference_depth_m = 0.0;     ///< the reference's puncture depth (m; NaN if none)
  std::size_t window_samples = 0;     ///< reference samples the scale was fitted on
  /// Force RMSE over them with s_k = 1 and with the identified s_k (N; NaN
  /// when the factor was not fitted: fewer than two samples).
  double window_rmse_before_N = std::numeric_limits<double>::quiet_NaN();
  double window_rmse_after_N = std::numeric_limits<double>::quiet_NaN();
  std::string note;                   ///< why not identified (empty when identified)
  std::string stiffness_note;         ///< why the factor was kept at 1 (empty when fitted)
  bool stiffness_scale_near_bound() const { return near_stiffness_scale_bound(stiffness_scale); }
};

struct ModelIdentification {
  std::string model;
  bool stiffness_identified = false;
  std::vector<LayerIdentification> layers;
  int model_runs = 0;
  double wall_time_s = 0.0;
  std::string joint_note;  ///< the joint step's outcome (empty: fewer than two layers fitted)
};

/// One line per model run and per identified layer (called from one thread at a time).
using IdentificationStepProgress = std::function<void(const std::string& line)>;

ModelIdentification identify_comparison_model(const std::string& model, const Scene& scene,
                                              std::shared_ptr<const meshing::TetMesh> mesh,
                                              const ReferenceData& reference, bool identify_stiffness,
                                              const IdentificationStepProgress& progress = {});

/// The model's scene: stiffness_scale (one per layer, 1 where not identified)
/// and each identified layer's breakthrough rule CriticalForce F_k.
Scene with_identified_parameters(const Scene& scene, const ModelIdentification& identification);

}  // namespace puncture::validation
