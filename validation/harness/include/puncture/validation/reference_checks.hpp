// reference_checks.hpp: whether a reference curve can be fitted at all, how
// sure its puncture detection is, and which parameters of each layer it can
// identify. calibrate() runs these before any model run.
//
// Errors (ReferenceError, message starting with the reference's file name;
// `puncture calibrate` exits 2 and writes nothing):
//   * no force above the noise: the insertion's largest |force| is 0 or below
//     min_peak_sigmas x the noise sigma (force_noise.hpp);
//   * no samples after contact: no contact onset (puncture_events.hpp), or no
//     insertion sample deeper than it;
//   * puncture detection unsure (force-drop source only, no depths given):
//     any of detection_doubts; the message asks for --puncture-depths;
//   * fewer insertion samples from the contact onset on than parameters to
//     tune (after the identifiability rule below).
// Identifiability of a layer's parameters (per layer, any reference counts):
//   * pressing group (K, k_s, L, w, stiffening): at least
//     kMinIdentifyingSamples insertion samples in the layer's pressing
//     segment (layer_segments);
//   * breakthrough parameter: a critical force or energy needs the
//     reference's puncture of the layer (its depth and force set it, whatever
//     K is; the default FEM's fat has a puncture but a single pressing
//     sample); the ring criterion's deformed threshold, a deflection read off
//     the pressing curve, needs the puncture and the pressing group;
//   * cut group (cutting force, friction, presliding): at least
//     kMinIdentifyingSamples insertion samples in the layer's after-puncture
//     segment.
// A parameter no reference identifies keeps its start value; calibrate()
// warns once per parameter (CalibrationResult::warnings).
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "puncture/validation/metrics.hpp"
#include "puncture/validation/puncture_events.hpp"

namespace puncture::validation {

/// A reference that cannot be fitted, or whose punctures are a guess (bad input).
class ReferenceError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

constexpr std::size_t kMinIdentifyingSamples = 3;

/// Why the k-th-drop-is-layer-k assignment of a force-drop reference is a
/// guess (empty: it is not): a marginal drop; more clear drops than layers;
/// fewer drops than layers whose undeformed bottom (top + thickness) lies
/// above the deepest insertion sample. Each entry is a sentence fragment.
std::vector<std::string> detection_doubts(const ReferenceEvents& events, const std::vector<LayerGeometry>& layers);

/// Insertion samples deeper than the contact onset (0 without one).
std::size_t samples_after_contact(const InsertionCurve& curve, const ReferenceEvents& events);

/// Throws ReferenceError for the first three errors of the header comment.
/// depths_given: the user gave the puncture depths (no detection doubt applies).
void check_reference_fittable(const InsertionCurve& curve, const ReferenceEvents& events, bool depths_given,
                              const PunctureDetectionOptions& options);

struct LayerIdentifiability {
  std::size_t pressing_samples = 0;
  std::size_t cut_samples = 0;
  bool punctured = false;
  bool pressing() const { return pressing_samples >= kMinIdentifyingSamples; }
  bool cut() const { return cut_samples >= kMinIdentifyingSamples; }
};
/// One entry per layer of `layers`.
std::vector<LayerIdentifiability> layer_identifiability(const InsertionCurve& curve, const ReferenceEvents& events,
                                                        const std::vector<LayerGeometry>& layers);

/// Throws ReferenceError when the curve has fewer samples after contact than
/// `tuned_parameters`, or when none of `requested_parameters` (> 0) is
/// identified (tuned_parameters == 0).
void check_enough_samples(const InsertionCurve& curve, const ReferenceEvents& events, std::size_t tuned_parameters,
                          std::size_t requested_parameters);

}  // namespace puncture::validation
