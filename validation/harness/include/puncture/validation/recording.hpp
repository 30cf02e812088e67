// recording.hpp: reading a reference recording into an InsertionCurve
// (metrics.hpp), whichever of two forms it has.
//
// 1. An insertion curve in the reader's schema (depth_mm, force_N and the
//    optional columns of metrics.hpp): read_insertion_curve /
//    parse_insertion_curve (curve_reader.cpp). `depth_mm,force_N` files read
//    as they always did.
// 2. A raw rig recording as the rig writes it: a time column, a stage
//    position column and a force column (any names, any other columns
//    ignored; "# ..." comment lines before the header), with an approach
//    before contact, the insertion, a hold and the withdrawal in one file.
//    Its RecordingFormat says which column is which, their units, the sign
//    of the force and the direction of the stage; it comes from a JSON
//    sidecar (`<recording stem>.json` beside the CSV, or any file given as
//    --recording-format) and/or command-line options (which win field by
//    field). Sidecar:
//      { "time":     { "column": "t_us",     "unit": "us" },
//        "position": { "column": "stage_mm", "unit": "mm", "into_tissue": "increasing" },
//        "force":    { "column": "Fz_N",     "unit": "N",  "sign": 1 } }
//    units: time s | ms | us; position m | mm | um; force N | mN. A unit may
//    be left out when the column name ends in "_<unit>" (t_us, stage_mm,
//    Fz_N). into_tissue: "increasing" when the stage position grows as the
//    needle goes into the tissue, "decreasing" otherwise. sign: +1 when the
//    file's force is positive while the tissue resists the insertion, -1
//    when it is negative then. Every field but the units is required; an
//    unknown key is an error. Errors (RecordingError, exit code 2 in the
//    commands) name the file and the field (`rig.json: field
//    'position.into_tissue': ...`) or the CSV file, line and column.
//    The conversion (curve_from_raw_recording, raw_recording.cpp):
//      * time in s from the first sample; stage travel s into the tissue (m);
//        force in N, positive against the insertion;
//      * phases from the position: the insertion up to the first sample
//        within kStageRestTolerance of the deepest position (a stage moving
//        back during it by more than that is an error; smaller back-steps,
//        an encoder's jitter, are clamped), the hold while the stage stays
//        within it, then the withdrawal (a stage moving in again by more than
//        that is an error); a stage that travels less than kMinStageTravel_m
//        is an error ("does not move");
//      * the force's noise sigma from the insertion samples, by the same
//        estimate the puncture detector uses (force_noise.hpp); a force that
//        never leaves the noise (largest excursion from the starting level
//        below PunctureDetectionOptions::min_peak_sigmas sigma) is an error;
//      * contact and tare together (noise-aware): over the insertion samples
//        up to where the force first rises by max(kContactFitRise x its
//        rise to the first peak (its largest force before the first force
//        drop, detect_force_drops; the whole insertion without one),
//        20 sigma) above its starting level, a
//        least-squares fit of "F0 before the contact s_c, then F0 +
//        a (s - s_c)^p" (a >= 0, p from 1 to 3 in steps of 0.1: a Hertz-like
//        rise) over every candidate s_c (each sample's position, then refined
//        between samples): the tare is F0 (the mean force before contact),
//        the contact s_c;
//        fewer than kMinNoiseSamples samples before the contact is an error
//        (the recording starts in contact: nothing to tare from);
//      * depth = s - s_c (negative in the approach), force = F - F0, phases
//        insertion (approach included) / dwell (the hold) / withdrawal, the
//        velocity of each phase its median stage speed; metadata
//        speed_mm_per_s and withdrawal_speed_mm_per_s (what calibration runs
//        the model at), recording_format, tare_N, noise_N, contact_time_s
//        and contact_<position column> (the stage position at contact, in
//        the file's unit: contact_stage_mm).
// read_reference_recording picks the form: a format given (file or options)
// or a sidecar present -> raw; else the curve schema (and when that lacks
// depth_mm, the error says how to describe a raw recording).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "puncture/io/csv_reader.hpp"
#include "puncture/validation/metrics.hpp"
#include "puncture/validation/reference_checks.hpp"

namespace puncture::validation {

InsertionCurve read_insertion_curve(const std::filesystem::path& path);
InsertionCurve parse_insertion_curve(const std::string& text, const std::string& source_name);
/// A curve file's bytes, and its text parsed as CSV; either problem as a
/// CurveFormatError naming the file (and line and column). Shared by the
/// curve and surface-profile readers.
std::string read_curve_file_bytes(const std::filesystem::path& path);
io::CsvDocument parse_curve_csv(const std::string& text, const std::string& source_name);

/// A raw recording or its format that cannot be read (bad input): the message
/// starts with the file and names the field or column.
class RecordingError : public ReferenceError {
 public:
  RecordingError(const std::string& file, const std::string& field, const std::string& what);
};

constexpr double kMinStageTravel_m = 0.1e-3;     ///< less stage travel than this: "does not move"
constexpr double kStageRestTolerance_m = 2e-6;   ///< positions this close count as one (encoder jitter)
constexpr double kContactFitRise = 0.8;          ///< the contact fit ends at this fraction of the rise to the first peak
/// Exponents p of the contact fit's rise a (s - s_c)^p: from, to, step.
constexpr double kContactExponents[3] = {1.0, 3.0, 0.1};

enum class StageDirection { Unset, Increasing, Decreasing };

struct RecordingColumn {
  std::string name;  ///< header name in the CSV; empty: not set
  std::string unit;  ///< empty: from the name's "_<unit>" suffix
};

struct RecordingFormat {
  std::string source;  ///< where it was read from (sidecar path, "command line"), for messages
  RecordingColumn time, position, force;
  StageDirection into_tissue = StageDirection::Unset;
  int force_sign = 0;  ///< +1 or -1; 0: not set
  /// True when no field is set (no format given).
  bool empty() const;
};

/// Parses a sidecar (see the header); throws RecordingError naming `source` and the field.
RecordingFormat parse_recording_format(const std::string& json_text, const std::string& source);
RecordingFormat read_recording_format(const std::filesystem::path& path);
/// `base` with every field that `overrides` sets replaced (source: both named).
RecordingFormat merge_recording_formats(const RecordingFormat& base, const RecordingFormat& overrides);
/// Seconds, metres or newtons per unit of a column; throws RecordingError
/// (file = format.source, field e.g. "time.unit") for a missing or unknown unit.
double unit_factor(const RecordingFormat& format, const RecordingColumn& column, const std::string& field,
                   const char* quantity);
/// Throws RecordingError for the first field missing or invalid.
void check_recording_format(const RecordingFormat& format);

/// What the conversion found (for reports and the detection plot).
struct RecordingAnalysis {
  double tare_N = 0.0;               ///< force subtracted (the mean before contact)
  double noise_N = 0.0;              ///< the force's noise sigma (force_noise.hpp)
  double contact_time_s = 0.0;       ///< from the first sample
  double contact_stage = 0.0;        ///< stage position at contact, in the file's unit
  std::size_t hold_from = 0, withdrawal_from = 0;  ///< first sample of each phase (size(): none)
  double insertion_speed_m_per_s = 0.0, withdrawal_speed_m_per_s = 0.0;
};

struct RawRecording {
  InsertionCurve curve;
  RecordingAnalysis analysis;
};

/// The conversion of the header on a parsed CSV (doc.source names the file).
RawRecording curve_from_raw_recording(const io::CsvDocument& doc, const RecordingFormat& format);

/// How a reference recording is to be read: a format file and/or options.
struct ReferenceRecordingOptions {
  std::filesystem::path format_file;  ///< --recording-format; empty: the sidecar if present
  RecordingFormat overrides;          ///< command-line fields
};
/// The sidecar path of a recording: the CSV's path with the extension ".json".
std::filesystem::path recording_sidecar_path(const std::filesystem::path& csv);
/// Reads a reference recording in either form (see the header).
InsertionCurve read_reference_recording(const std::filesystem::path& csv, const ReferenceRecordingOptions& options = {});

}  // namespace puncture::validation
