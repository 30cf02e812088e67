// puncture_events.hpp: where the layers of a reference curve break, and the
// depth segments of an insertion that belong to each layer.
//
// Sources of a reference's punctures, in order of preference:
//   * given depths (the user knows them: `puncture calibrate --puncture-depths`),
//     one per layer from the top; the force is the largest insertion force
//     within the detection window before the depth;
//   * <layer>_state columns: the first insertion sample whose state is
//     punctured (puncture_event in metrics.hpp);
//   * force drops (a measured curve with depth and force only,
//     detect_force_drops, force_drops.cpp). The force's noise sigma is
//     estimated from the curve itself (force_noise.hpp; ~0 on a finely
//     sampled model or FEM curve, where the rules below reduce to the
//     noiseless ones). A drop starts at an insertion sample F_p (a local
//     maximum, or a sample of a plateau that sags into the fall) after which
//     the force falls by at least max(min_drop_fraction F_p,
//     min_drop_of_peak x the curve's peak, min_drop_sigmas sigma) by the next
//     sample or before the tip has advanced window_m beyond it (and before it
//     rises above F_p again; the next sample counts however coarse the
//     sampling), with F_p itself at least min_peak_sigmas sigma (noise near
//     zero force is no drop), and which the force rose into from below: F_p
//     exceeds the lowest force since the previous drop's lowest sample (or
//     the start of the insertion) by at least min_rise_of_drop x the drop and
//     noise_band_sigmas sigma. A puncture ends the pressing of a layer, whatever comes after it
//     (a softer cut, or a stiffer layer pressed next) and whatever the
//     maximum's plateau does (flat or sagging); a cut that ends on an
//     unloaded layer below (a model without layer interaction) also drops the
//     force, but from a plateau it entered from above (the previous
//     puncture), which the rise rule rejects. The fall starts at the knee
//     between the maximum and the lowest sample of the fall: of the samples
//     still above the fall's middle, the one farthest above the straight
//     line from the maximum to the lowest sample (the maximum itself when the force falls at once; the end of a sag or
//     plateau before a steep fall). The drop's depth is that of the first
//     sample after the fall's start (without noise and with a one-sample
//     fall, the sample after the maximum, as a state column would mark it),
//     its force F_p (on a noisy curve biased up by about a sigma).
//     Candidates whose maximum lies inside the previous drop's fall, or
//     closer than window_m, are one drop (the larger wins): a drop spread
//     over many samples counts once, several drops in one layer (a liver's
//     vessels) each count. A drop below clear_drop_sigmas sigma is marginal.
//     The k-th drop is layer k's puncture. ReferenceEvents::doubts lists why
//     that assignment is a guess (reference_checks.hpp, detection_doubts):
//     a marginal drop; more clear drops than layers (the largest are kept);
//     fewer drops than the layers whose undeformed bottom the curve's
//     deepest sample passes. Calibration stops on any doubt and asks for
//     the puncture depths.
//   Contact onset (no states): where the reader knows it
//   (InsertionCurve::known_contact_depth_m: a raw recording's contact fit),
//   else the first insertion sample whose force
//   exceeds max(onset_fraction x the peak, noise_band_sigmas sigma) and stays
//   above it over the next onset_hold_m of depth (at least the next sample).
//
// Layer segments (layer_segments), from the reference's puncture depths P_k
// and the scene's layer geometry (top depth, thickness t_k, bottom b_k):
//   pressing k:  [start_k, P_k)  with start_0 = the contact onset (first
//                insertion sample pressed, or above 1 % of the peak force
//                without states) and start_k = end of after_(k-1);
//                to the deepest sample if layer k has no puncture;
//   after k:     [P_k, E_k) where the tip cuts through layer k (cutting and
//                friction): E_k = b_k when the puncture is above the layer's
//                bottom, else P_k + t_k (a thin layer pressed deeper than its
//                thickness is cut through from where it broke), at most the
//                next puncture and the deepest sample; with the force's
//                parts, at most where the reference's tip force is back
//                above 0 (ReferenceEvents::cut_end_m). compare_trajectory
//                also ends it where the model's tip meets the next layer
//                when the reference has no parts.
// A layer the reference does not reach has neither segment.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "puncture/scene.hpp"
#include "puncture/validation/metrics.hpp"

namespace puncture::validation {

struct PunctureDetectionOptions {
  double min_drop_fraction = 0.1;  ///< a drop is at least this fraction of the force at its maximum
  double min_drop_of_peak = 0.02;  ///< and at least this fraction of the curve's peak force
  double window_m = 0.25e-3;       ///< the drop happens within this much further insertion (m)
  double onset_fraction = 0.01;    ///< contact onset: first force above this fraction of the peak (no states)
  double onset_hold_m = 0.1e-3;    ///< ... that stays above it over this much further depth (m)
  double min_drop_sigmas = 8.0;    ///< a drop is at least this many noise deviations
  double clear_drop_sigmas = 12.0; ///< a drop below this many noise deviations is marginal
  double min_peak_sigmas = 10.0;   ///< the force at the maximum is at least this many noise deviations
  double noise_band_sigmas = 3.0;  ///< force within this many deviations is at one level (rise, contact)
  double min_rise_of_drop = 0.5;   ///< the rise into the maximum is at least this fraction of the drop
};

struct ForceDrop {
  std::size_t index = 0;    ///< curve sample of F_p (the maximum, or a sample of a sagging plateau)
  double depth_m = 0.0;     ///< depth of the first sample after the fall's start (its knee; see the header)
  double peak_force_N = 0.0;
  double drop_N = 0.0;
  double noise_sigmas = 0.0;  ///< drop_N / the curve's noise sigma (infinity without noise)
  bool marginal = false;      ///< below clear_drop_sigmas sigma
};

/// Every force drop of the insertion phase that passes the thresholds, in depth order.
std::vector<ForceDrop> detect_force_drops(const InsertionCurve& curve, const PunctureDetectionOptions& options = {});
/// The same with the insertion force's noise sigma (N) already estimated (force_noise.hpp).
std::vector<ForceDrop> detect_force_drops(const InsertionCurve& curve, double noise_sigma_N,
                                          const PunctureDetectionOptions& options);

/// Contact onset from the force alone (see the header): depth (m) of the
/// first insertion sample (`phase`) above the threshold that holds; false if none.
bool contact_onset_from_force(const InsertionCurve& curve, const std::vector<std::size_t>& phase, double sigma_N,
                              const PunctureDetectionOptions& options, double& onset_m);

enum class PunctureSource { GivenDepths, StateColumns, ForceDrops };
const char* to_string(PunctureSource source);

struct LayerGeometry {
  std::string name;
  double top_depth_m = 0.0;
  double thickness_m = 0.0;
  double spacing_L_m = 0.0;  ///< the layer's force-mesh spacing (puncture-depth accuracy)
};
std::vector<LayerGeometry> layer_geometry(const Scene& scene);

/// A reference's punctures, one entry per layer (top first).
struct ReferenceEvents {
  PunctureSource source = PunctureSource::ForceDrops;
  std::vector<PunctureEventMetrics> punctures;  ///< per layer of the geometry
  bool has_contact_onset = false;
  double contact_onset_m = 0.0;
  double deepest_m = 0.0;                       ///< deepest insertion sample
  std::vector<ForceDrop> drops;                 ///< every candidate drop found (ForceDrops source)
  /// Per layer: where the cut through it ends (cut_end_from_parts); NaN when
  /// the curve has no part columns or does not say.
  std::vector<double> cut_end_m;
  std::string note;                             ///< how they were found, for reports
  double noise_N = 0.0;                         ///< the insertion force's noise sigma (force_noise.hpp)
  /// ForceDrops source: why the drop-to-layer assignment is a guess (empty:
  /// it is not); see detection_doubts in reference_checks.hpp.
  std::vector<std::string> doubts;
};

/// Where the cut through a layer punctured at puncture_depth_m ends, from a
/// curve's parts (`samples`: its insertion samples in depth order; forces at
/// or below zero_N count as 0):
///  - the tip force at 0 after the drop's own sample (the tip cuts alone):
///    the first later sample with the tip force > 0 (the next layer pressed);
///  - the tip force > 0 from the sample after the drop on (the next layer met
///    at the break): with the cutting force at 0 there, no cut (the puncture
///    depth itself); with it > 0 (the squeezed layer cut while the next one is
///    pressed), the first sample with the cutting force back at 0;
/// NaN when the curve does not say (no parts, no sample after the drop, or a
/// cut that lasts to the end).
double cut_end_from_parts(const InsertionCurve& curve, const std::vector<std::size_t>& samples,
                          double puncture_depth_m, double zero_N);

/// given_depths_m: empty, or one depth per layer from the top (fewer: the
/// layers below are not punctured). Throws std::invalid_argument for given
/// depths that do not increase or lie outside the insertion.
ReferenceEvents reference_events(const InsertionCurve& reference, const std::vector<LayerGeometry>& layers,
                                 const std::vector<double>& given_depths_m = {},
                                 const PunctureDetectionOptions& options = {});

struct LayerSegments {
  bool has_pressing = false;
  double pressing_from_m = 0.0, pressing_to_m = 0.0;
  bool has_after = false;
  double after_from_m = 0.0, after_to_m = 0.0;
};
/// One entry per layer (see the header comment).
std::vector<LayerSegments> layer_segments(const ReferenceEvents& events, const std::vector<LayerGeometry>& layers);

}  // namespace puncture::validation
