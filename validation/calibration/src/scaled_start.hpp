// scaled_start.hpp (internal to puncture_calibration): the start point of a
// layer's stage, scaled to the first reference.
//
// Scaled start of a layer's stage (up to eight passes), against the first
// reference: K (and k_s when tuned, keeping K / k_s and so the ring
// profile) scaled by the ratio of the reference's pressing slope to the
// model's; the breakthrough parameter scaled to the reference's puncture
// (threshold by the ratio of the breakthrough deflections, critical energy
// by the squared deflection ratio; the critical force from the layer's
// fracture toughness, G_c x needle diameter, when the scene gives G_c, else
// set to the reference's puncture force minus the model's friction and
// cutting there); then
// cutting and friction from a least-squares fit of the force difference on
// the layer's cut (level and slope with the shaft length) and, with a
// withdrawal, of the withdrawal force inside the layer (friction only).
// Values stay inside the bounds.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "calibration_parameters.hpp"
#include "puncture/validation/calibration.hpp"

namespace puncture::validation::calibration_detail {

Scene scaled_start(const Scene& candidate, std::size_t k, const ReferenceCurve& reference, const ReferenceEvents& ref_ev,
                   const std::vector<LayerGeometry>& layers, const CalibrationOptions& options, const SurfaceCache& cache,
                   const std::vector<Parameter>& parameters);

/// The critical-force starts of the scaled start, in words (empty without scaled_start).
std::string critical_force_start_note(const Scene& scene, const std::vector<std::size_t>& layers,
                                      const CalibrationOptions& options);

/// The start of the breakthrough rate exponent n of each layer in `layers`
/// whose critical force is tuned (`level_tuned`), from the references'
/// punctures of it at two or more speeds: the slope of ln F against ln v
/// (least squares), clamped to n's bounds [0, 1]; the layer stage then fits
/// F_c at that n (started at n = 0 it fits one F_c to every speed, a
/// compromise the rate stage could not undo). A note per layer started so.
Scene rate_exponent_start(const Scene& scene, const std::vector<std::size_t>& layers,
                          const std::vector<bool>& level_tuned, const std::vector<ReferenceCurve>& references,
                          const std::vector<ReferenceEvents>& events, std::vector<std::string>& notes);

}  // namespace puncture::validation::calibration_detail
