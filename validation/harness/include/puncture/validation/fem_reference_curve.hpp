// fem_reference_curve.hpp: the FEM reference of a scene as a calibration
// reference curve, and the scene at another insertion speed.
//
// fem_insertion_curve(scene, csv): reads the FEM's fem_force_depth.csv
//   (time s, depth mm, velocity mm/s, force N, parts, layer states) and adds
//   the metadata calibration reads:
//     speed_mm_per_s, withdrawal_speed_mm_per_s  the scene's trajectory;
//     rate_dependent: true                        when a layer of the scene is
//       viscoelastic (Prony terms): the FEM's force then depends on the
//       insertion speed, so references at two or more speeds carry what the
//       real-time damping d (Table 1: d h v) is identified from;
//     quasi_static: true                          otherwise.
// scene_at_insertion_speed(scene, v): the same scene inserted and withdrawn
//   at v (m/s > 0; std::invalid_argument otherwise), named
//   "<name>_<v mm/s>mm_per_s"; every other field unchanged, so its FEM
//   reference differs from the scene's only by the speed.
#pragma once

#include <filesystem>

#include "puncture/scene.hpp"
#include "puncture/validation/metrics.hpp"

namespace puncture::validation {

/// True when a layer has Prony relaxation terms.
bool scene_is_viscoelastic(const Scene& scene);

InsertionCurve fem_insertion_curve(const Scene& scene, const std::filesystem::path& fem_force_depth_csv);

Scene scene_at_insertion_speed(const Scene& scene, double speed_m_per_s);

}  // namespace puncture::validation
