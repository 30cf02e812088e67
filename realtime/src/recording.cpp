#include "puncture/realtime/recording.hpp"

#include <unistd.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "byte_order.hpp"

namespace puncture::realtime {
namespace {

using namespace le;

constexpr char kMagic[8] = {'P', 'N', 'C', 'R', 'E', 'C', '1', '\n'};
constexpr std::uint32_t kFormatVersion = 1;
constexpr std::size_t kPreamble = 24;

void put_doubles(std::uint8_t* p, const double* v, int n) noexcept {
  for (int i = 0; i < n; ++i) put_f64(p + 8 * i, v[i]);
}
void get_doubles(const std::uint8_t* p, double* v, int n) noexcept {
  for (int i = 0; i < n; ++i) v[i] = get_f64(p + 8 * i);
}

}  // namespace

NeedleState TickRecord::needle() const {
  NeedleState s;
  s.time_s = needle_time_s;
  s.tip_position_m = Eigen::Vector3d(tip_m[0], tip_m[1], tip_m[2]);
  s.direction = Eigen::Vector3d(direction[0], direction[1], direction[2]);
  s.axial_velocity_m_per_s = axial_velocity_m_per_s;
  return s;
}

TickOutputs TickRecord::outputs() const {
  TickOutputs o;
  o.tissue_force_N = tissue_force_N;
  o.force_raw_N = Eigen::Vector3d(force_raw_N[0], force_raw_N[1], force_raw_N[2]);
  o.force_sent_N = Eigen::Vector3d(force_sent_N[0], force_sent_N[1], force_sent_N[2]);
  o.layer_states = layer_states;
  return o;
}

void encode_record(const TickRecord& r, std::uint8_t (&out)[kRecordSize]) noexcept {
  put_u64(out + 0, r.tick);
  put_u32(out + 8, r.flags);
  put_u32(out + 12, r.layer_states);
  put_f64(out + 16, r.wall_time_s);
  put_f64(out + 24, r.needle_time_s);
  put_doubles(out + 32, r.tip_m, 3);
  put_doubles(out + 56, r.direction, 3);
  put_f64(out + 80, r.axial_velocity_m_per_s);
  put_doubles(out + 88, r.pose_position_m, 3);
  put_doubles(out + 112, r.pose_orientation_wxyz, 4);
  put_f64(out + 144, r.tissue_force_N);
  put_doubles(out + 152, r.force_raw_N, 3);
  put_doubles(out + 176, r.force_sent_N, 3);
  put_f64(out + 200, r.depth_m);
}

TickRecord decode_record(const std::uint8_t* in) noexcept {
  TickRecord r;
  r.tick = get_u64(in + 0);
  r.flags = get_u32(in + 8);
  r.layer_states = get_u32(in + 12);
  r.wall_time_s = get_f64(in + 16);
  r.needle_time_s = get_f64(in + 24);
  get_doubles(in + 32, r.tip_m, 3);
  get_doubles(in + 56, r.direction, 3);
  r.axial_velocity_m_per_s = get_f64(in + 80);
  get_doubles(in + 88, r.pose_position_m, 3);
  get_doubles(in + 112, r.pose_orientation_wxyz, 4);
  r.tissue_force_N = get_f64(in + 144);
  get_doubles(in + 152, r.force_raw_N, 3);
  get_doubles(in + 176, r.force_sent_N, 3);
  r.depth_m = get_f64(in + 200);
  return r;
}

// ---------------------------------------------------------------- writer

nlohmann::json recording_header(const Scene& scene, const std::string& scene_file, const std::string& scene_text,
                                const std::string& device_name, const nlohmann::json& provenance) {
  nlohmann::json header = {{"format", "puncture-recording"},
                           {"version", 1},
                           {"scene_file", scene_file},
                           {"scene_text", scene_text},
                           {"device", device_name},
                           {"haptic_rate_Hz", scene.realtime.haptic_rate_Hz},
                           {"provenance", provenance}};
  nlohmann::json names = nlohmann::json::array();
  for (const Layer& l : scene.layers) names.push_back(l.name);
  header["layers"] = names;
  return header;
}

RecordingWriter::RecordingWriter(const std::filesystem::path& path, const nlohmann::json& header,
                                 std::size_t ring_capacity)
    : path_(path), partial_(path.string() + ".partial"), ring_(ring_capacity) {
  file_ = std::fopen(partial_.c_str(), "wb");
  if (!file_) throw std::runtime_error(path_.string() + ": cannot create recording (" + std::strerror(errno) + ")");
  const std::string text = header.dump();
  std::uint8_t pre[kPreamble];
  std::memcpy(pre, kMagic, 8);
  put_u32(pre + 8, kFormatVersion);
  put_u32(pre + 12, static_cast<std::uint32_t>(kRecordSize));
  put_u64(pre + 16, text.size());
  if (std::fwrite(pre, 1, kPreamble, file_) != kPreamble || std::fwrite(text.data(), 1, text.size(), file_) != text.size()) {
    abandon();
    throw std::runtime_error(path_.string() + ": cannot write the recording header");
  }
  thread_ = std::thread([this] {
    while (!done_.load(std::memory_order_acquire)) {
      drain();
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    drain();
  });
}

RecordingWriter::~RecordingWriter() {
  if (thread_.joinable()) {
    done_.store(true, std::memory_order_release);
    thread_.join();
  }
  if (file_) abandon();
}

bool RecordingWriter::push(const TickRecord& record) noexcept {
  if (ring_.try_push(record)) return true;
  dropped_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

void RecordingWriter::drain() {
  TickRecord r;
  std::uint8_t bytes[kRecordSize];
  while (ring_.try_pop(r)) {
    encode_record(r, bytes);
    if (std::fwrite(bytes, 1, kRecordSize, file_) != kRecordSize) write_failed_ = true;
    ++written_;
  }
}

void RecordingWriter::abandon() noexcept {
  if (file_) std::fclose(file_);
  file_ = nullptr;
  std::error_code ec;
  std::filesystem::remove(partial_, ec);
}

std::int64_t RecordingWriter::finish() {
  if (thread_.joinable()) {
    done_.store(true, std::memory_order_release);
    thread_.join();
  }
  if (!file_) throw std::runtime_error(path_.string() + ": recording already finished");
  if (dropped() > 0) {
    abandon();
    throw std::runtime_error(path_.string() + ": " + std::to_string(dropped()) +
                             " records could not be queued (the disk did not keep up); recording discarded");
  }
  const bool flushed = std::fflush(file_) == 0 && ::fsync(fileno(file_)) == 0;
  if (write_failed_ || !flushed) {
    abandon();
    throw std::runtime_error(path_.string() + ": writing the recording failed; recording discarded");
  }
  std::fclose(file_);
  file_ = nullptr;
  std::error_code ec;
  std::filesystem::rename(partial_, path_, ec);
  if (ec) {
    std::filesystem::remove(partial_, ec);
    throw std::runtime_error(path_.string() + ": cannot rename the finished recording: " + ec.message());
  }
  return written_;
}

// ---------------------------------------------------------------- reader

std::string Recording::scene_text() const { return header.at("scene_text").get<std::string>(); }

Recording read_recording(const std::filesystem::path& path) {
  const std::string where = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(where + ": cannot open recording");
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto* p = reinterpret_cast<const std::uint8_t*>(bytes.data());
  if (bytes.size() < kPreamble || std::memcmp(p, kMagic, 8) != 0)
    throw std::runtime_error(where + ": not a puncture recording (bad magic)");
  const std::uint32_t version = get_u32(p + 8);
  if (version != kFormatVersion)
    throw std::runtime_error(where + ": recording format version " + std::to_string(version) +
                             " (this program reads version " + std::to_string(kFormatVersion) + ")");
  const std::uint32_t record_size = get_u32(p + 12);
  if (record_size != kRecordSize)
    throw std::runtime_error(where + ": record size " + std::to_string(record_size) + " (expected " +
                             std::to_string(kRecordSize) + ")");
  const std::uint64_t header_length = get_u64(p + 16);
  if (header_length > bytes.size() - kPreamble) throw std::runtime_error(where + ": truncated header");
  Recording rec;
  try {
    rec.header = nlohmann::json::parse(bytes.begin() + kPreamble, bytes.begin() + static_cast<long>(kPreamble + header_length));
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(where + ": header is not valid JSON: " + e.what());
  }
  if (!rec.header.is_object() || rec.header.value("format", "") != "puncture-recording" ||
      !rec.header.contains("scene_text") || !rec.header["scene_text"].is_string())
    throw std::runtime_error(where + ": header lacks format \"puncture-recording\" or scene_text");
  const std::size_t body = bytes.size() - kPreamble - header_length;
  if (body % kRecordSize != 0)
    throw std::runtime_error(where + ": truncated record at the end (" + std::to_string(body % kRecordSize) +
                             " stray bytes)");
  const std::size_t n = body / kRecordSize;
  rec.records.reserve(n);
  const std::uint8_t* r = p + kPreamble + header_length;
  for (std::size_t i = 0; i < n; ++i) rec.records.push_back(decode_record(r + i * kRecordSize));
  return rec;
}

void write_recording_csv(const Recording& recording, const std::filesystem::path& csv_path) {
  const std::filesystem::path partial = csv_path.string() + ".partial";
  {
    std::ofstream out(partial);
    if (!out) throw std::runtime_error(csv_path.string() + ": cannot create CSV");
    out << "tick,flags,layer_states,wall_time_s,needle_time_s,tip_x_m,tip_y_m,tip_z_m,dir_x,dir_y,dir_z,"
           "axial_velocity_m_per_s,pose_x_m,pose_y_m,pose_z_m,pose_qw,pose_qx,pose_qy,pose_qz,tissue_force_N,"
           "force_raw_x_N,force_raw_y_N,force_raw_z_N,force_sent_x_N,force_sent_y_N,force_sent_z_N,depth_m\n";
    out << std::setprecision(17);
    for (const TickRecord& r : recording.records) {
      out << r.tick << ',' << r.flags << ',' << r.layer_states << ',' << r.wall_time_s << ',' << r.needle_time_s;
      for (double v : r.tip_m) out << ',' << v;
      for (double v : r.direction) out << ',' << v;
      out << ',' << r.axial_velocity_m_per_s;
      for (double v : r.pose_position_m) out << ',' << v;
      for (double v : r.pose_orientation_wxyz) out << ',' << v;
      out << ',' << r.tissue_force_N;
      for (double v : r.force_raw_N) out << ',' << v;
      for (double v : r.force_sent_N) out << ',' << v;
      out << ',' << r.depth_m << '\n';
    }
    if (!out.flush()) {
      std::error_code ec;
      std::filesystem::remove(partial, ec);
      throw std::runtime_error(csv_path.string() + ": writing the CSV failed");
    }
  }
  std::filesystem::rename(partial, csv_path);
}

}  // namespace puncture::realtime
