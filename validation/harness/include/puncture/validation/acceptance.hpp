// acceptance.hpp: does a model meet the per-layer acceptance of a tuned
// preset against its reference? Read from the whole-trajectory comparison
// (trajectory_objective.hpp), so validate and calibrate judge alike.
//
// In:  the layer geometry (puncture_events.hpp: name, L), the
//      TrajectoryComparison of the model against the reference, the criteria.
// Out: per layer (LayerAcceptance):
//   force RMSE over the layer's whole stretch of the insertion (its pressing
//     and its cut, i.e. the samples of the terms "pressing <layer>" and
//     "after_puncture <layer>", combined as sqrt(sum n_i v_i^2 / sum n_i)),
//     relative to the reference's insertion peak: <= max_rmse_relative;
//   puncture depth error (model - reference): |error| <= the layer's L;
//   puncture force error relative to the reference's puncture force:
//     |error| <= max_force_error_relative.
//   A criterion that cannot be computed (a term n/a, a puncture only one
//   curve has) is not met and says why.
// add_deflection_acceptance: with the surfaces compared (validate), also
//   the deflection RMSE of the layer's top surface before its breakthrough,
//   relative to the reference's largest deflection there: <=
//   max_deflection_relative; and after it (the recovery): <=
//   max_recovery_relative. A layer with those checks is accepted only when
//   they are met as well; calibration judges without them.
// acceptance_markdown: the table (with "n/a" and the reason, never 0) and the
//   whole-trajectory terms (overall, withdrawal, dwell) below it.
#pragma once

#include <string>
#include <vector>

#include "puncture/validation/puncture_events.hpp"
#include "puncture/validation/trajectory_objective.hpp"

namespace puncture::validation {

struct AcceptanceCriteria {
  double max_rmse_relative = 0.10;         ///< force RMSE / reference peak, per layer
  double max_force_error_relative = 0.10;  ///< |puncture force error| / reference puncture force
  double max_deflection_relative = 0.15;   ///< deflection RMSE before the breakthrough / reference's largest
  double max_recovery_relative = 0.25;     ///< deflection RMSE after the breakthrough / reference's largest
};

struct AcceptanceCheck {
  bool available = false;
  double value = 0.0;   ///< rmse_relative, depth error (m) or force error (relative)
  double limit = 0.0;   ///< same unit as value
  bool met = false;
  std::string note;     ///< why it is n/a, or what was compared
};

struct LayerAcceptance {
  std::string layer;
  std::size_t rmse_samples = 0;
  AcceptanceCheck force_rmse, puncture_depth, puncture_force;
  bool deflection_judged = false;        ///< set by add_deflection_acceptance
  AcceptanceCheck deflection, recovery;  ///< relative RMSE before and after the breakthrough
  bool accepted() const {
    return force_rmse.met && puncture_depth.met && puncture_force.met &&
           (!deflection_judged || (deflection.met && recovery.met));
  }
};

/// One layer's surface comparison: relative RMSEs (NaN or unavailable: not compared, note says why).
struct LayerDeflectionErrors {
  bool before_available = false, after_available = false;
  double before_relative = 0.0, after_relative = 0.0;
  std::string note;
};

std::vector<LayerAcceptance> layer_acceptance(const std::vector<LayerGeometry>& layers,
                                              const TrajectoryComparison& comparison,
                                              const AcceptanceCriteria& criteria = {});

/// Adds the deflection checks (errors[k] for acceptance[k]; sizes must match).
void add_deflection_acceptance(std::vector<LayerAcceptance>& acceptance, const std::vector<LayerDeflectionErrors>& errors,
                               const AcceptanceCriteria& criteria = {});

std::string acceptance_markdown(const std::vector<LayerAcceptance>& acceptance, const TrajectoryComparison& comparison,
                                const AcceptanceCriteria& criteria = {});

}  // namespace puncture::validation
