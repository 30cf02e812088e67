// scene_limits.hpp: limits that protect the machine from a scene file (or a
// typo in one): how long a run may be, how much it may keep in memory and
// write to disk. validate_scene (scene_io.hpp) enforces them with a
// SceneError naming the JSON path, so `puncture run` fails at once instead of
// running for minutes and ending in std::bad_alloc or a gigabyte CSV.
//
// Sizes are in the scene's units (mm where the key says so). Each limit is
// far beyond anything physical for a needle insertion, so no sensible scene
// meets it.
#pragma once

#include <cstddef>
#include <string>

#include "puncture/scene.hpp"

namespace puncture::scene_limits {

constexpr std::size_t kMaxSceneFileBytes = 4u << 20;       ///< a scene file is a few kB
constexpr std::size_t kMaxTextLength = 4096;               ///< name, description, source strings (characters)
constexpr std::size_t kMaxLayers = 16;
constexpr double kMaxLengthMm = 1000.0;                    ///< sample diameter, layer thickness, start height, L
constexpr double kMaxHapticRateHz = 100e3;                 ///< 100 kHz haptic loop
constexpr double kMaxDurationS = 3600.0;                   ///< scripted insertion incl. dwell and withdrawal
/// Ticks x (layers + 2) of one scripted run: every tick's result is kept in
/// memory (about 50 bytes per layer and tick) and is one CSV row.
constexpr double kMaxTickLayerProduct = 2e7;
/// VTK surface frames: files written (2 per layer and frame, ~100 kB each).
constexpr double kMaxFrameFiles = 6000.0;
/// realtime_curve.csv keeps at most this many rows; longer runs are
/// decimated (every k-th tick, plus every tick at which a layer's state
/// changes) with a warning in the console and in summary.json.
constexpr std::size_t kMaxCurveRows = 200000;
/// A needle force beyond this is reported as not physical (warning).
constexpr double kPlausibleForceN = 50.0;

/// Scripted insertion duration (s): approach + insertion at speed, dwell,
/// withdrawal back to the start height.
double scripted_duration_s(const Insertion& insertion);
/// Number of haptic ticks of the scripted insertion.
double scripted_ticks(const Scene& scene);

/// Throws SceneError (file, JSON path) for the first limit the scene breaks.
void check_scene_limits(const Scene& scene, const std::string& file);

}  // namespace puncture::scene_limits
