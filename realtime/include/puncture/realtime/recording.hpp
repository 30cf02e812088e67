// recording.hpp: recording a session tick by tick, reading it back, and
// replaying it through the model to check the forces bit for bit.
//
// File format (version 1), little-endian, doubles IEEE-754 binary64:
//   off  size  field
//     0     8  magic "PNCREC1\n"
//     8     4  u32 format version = 1
//    12     4  u32 record size R = 208
//    16     8  u64 header length H
//    24     H  header: UTF-8 JSON object with
//                "format": "puncture-recording", "version": 1,
//                "scene_file": path, "scene_text": the scene file's text verbatim,
//                "device": name, "haptic_rate_Hz", "layers": [names],
//                "provenance": {command, program_version, git_revision, date_utc, machine}
//  24+H  n * R  one record per model tick, in order, until the end of the file:
//     0  u64     tick: the session's haptic tick index
//     8  u32     flags: bit 0 fresh tissue (this tick ran on a new, untouched
//                model), bit 1 force magnitude clamped, bit 2 force rate clamped,
//                bit 3 no pose (needle held)
//    12  u32     layer states, 2 bits per layer (0 untouched, 1 pressed, 2 punctured)
//    16  f64     wall time of the tick's start since the session start (s)
//    24  f64     needle time (s)           -+
//    32  f64[3]  needle tip (m)             | the NeedleState fed to the model:
//    56  f64[3]  needle direction (unit)    | a replay feeds exactly these
//    80  f64     axial velocity (m/s)      -+
//    88  f64[3]  device pose position (m)
//   112  f64[4]  device pose orientation quaternion w, x, y, z
//   144  f64     tissue force along the needle (N, > 0 resisting insertion)
//   152  f64[3]  force on the needle before the guard (N, scene frame)
//   176  f64[3]  force sent to the device after the guard (N)
//   200  f64     tip depth below the skin surface (m)
// A file whose size is not 24 + H + n R is rejected (truncated record).
//
// RecordingWriter runs its own thread: the haptic thread push()es records
// into a lock-free ring (never waits; a full ring drops the record and counts
// it); the writer thread encodes and writes them to "<path>.partial", and
// finish() renames it to <path> only if nothing was dropped and every write
// succeeded (otherwise it removes the partial file and throws).
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "puncture/realtime/device.hpp"
#include "puncture/realtime/spsc_ring.hpp"
#include "puncture/scene.hpp"

namespace puncture::realtime {

constexpr std::size_t kRecordSize = 208;

enum RecordFlags : std::uint32_t {
  kRecFreshTissue = 1u << 0,
  kRecMagnitudeClamped = 1u << 1,
  kRecRateClamped = 1u << 2,
  kRecNoPose = 1u << 3,
};

struct TickRecord {
  std::uint64_t tick = 0;
  std::uint32_t flags = 0;
  std::uint32_t layer_states = 0;
  double wall_time_s = 0.0;
  double needle_time_s = 0.0;
  double tip_m[3] = {0, 0, 0};
  double direction[3] = {0, 0, -1};
  double axial_velocity_m_per_s = 0.0;
  double pose_position_m[3] = {0, 0, 0};
  double pose_orientation_wxyz[4] = {1, 0, 0, 0};
  double tissue_force_N = 0.0;
  double force_raw_N[3] = {0, 0, 0};
  double force_sent_N[3] = {0, 0, 0};
  double depth_m = 0.0;

  NeedleState needle() const;
  TickOutputs outputs() const;
};

void encode_record(const TickRecord& r, std::uint8_t (&out)[kRecordSize]) noexcept;
TickRecord decode_record(const std::uint8_t* in) noexcept;

/// The header of a session's recording (the JSON described above): `scene`'s
/// file name and text verbatim, its layer names and haptic rate (Hz), the
/// device's name and the session's provenance as given.
nlohmann::json recording_header(const Scene& scene, const std::string& scene_file, const std::string& scene_text,
                                const std::string& device_name, const nlohmann::json& provenance);

class RecordingWriter {
 public:
  /// Opens "<path>.partial" and writes the header; throws std::runtime_error on IO errors.
  RecordingWriter(const std::filesystem::path& path, const nlohmann::json& header, std::size_t ring_capacity = 1 << 16);
  ~RecordingWriter();  ///< without finish(): stops the thread and removes the partial file
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  /// Haptic thread: never blocks; false (and counted) when the ring is full.
  bool push(const TickRecord& record) noexcept;
  /// Drains, closes and renames; returns the number of records. Throws if records were dropped or a write failed.
  std::int64_t finish();
  std::int64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  const std::filesystem::path& path() const { return path_; }

 private:
  void drain();
  void abandon() noexcept;
  std::filesystem::path path_, partial_;
  std::FILE* file_ = nullptr;
  SpscRing<TickRecord> ring_;
  std::atomic<bool> done_{false};
  std::atomic<std::int64_t> dropped_{0};
  std::int64_t written_ = 0;
  bool write_failed_ = false;
  std::thread thread_;
};

struct Recording {
  nlohmann::json header;
  std::vector<TickRecord> records;
  std::string scene_text() const;
};

/// Reads and checks a recording; throws std::runtime_error naming the file
/// and what is wrong (magic, version, record size, header JSON, truncated record).
Recording read_recording(const std::filesystem::path& path);

/// One CSV row per record (the same fields, SI units, full precision).
void write_recording_csv(const Recording& recording, const std::filesystem::path& csv_path);

}  // namespace puncture::realtime
