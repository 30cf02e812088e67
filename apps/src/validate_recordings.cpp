// validate_recordings.cpp: `puncture validate --reference REC ...` (see the
// header): the scene's model against measured recordings, each on its own
// trajectory (speed, depth, hold and withdrawal from the recording).
#include "validate_recordings.hpp"

#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "command_errors.hpp"
#include "measured_reference.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/io/provenance_json.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/calibration.hpp"
#include "puncture/validation/calibration_report.hpp"
#include "puncture/validation/number_format.hpp"
#include "puncture/validation/recording.hpp"
#include "puncture/validation/recording_scatter.hpp"

namespace puncture::apps {
namespace {

std::string num(double x, int digits = 4) { return validation::significant_digits(x, digits); }

std::string command_line(const ValidateOptions& options, const std::filesystem::path& scene_path,
                         const std::filesystem::path& dir) {
  std::string c = "puncture validate " + scene_path.string();
  for (const std::filesystem::path& r : options.references) c += " --reference " + r.string();
  if (!options.recording.format_file.empty()) c += " --recording-format " + options.recording.format_file.string();
  return c + " -o " + dir.string();
}

/// Per recording: its layers' punctures (recording -> model), as text.
std::string punctures_text(const validation::JudgedRecording& j, const Scene& scene) {
  std::string s;
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const bool r = k < j.events.punctures.size() && j.events.punctures[k].found;
    const bool m = k < j.after.model_punctures.size() && j.after.model_punctures[k].found;
    if (!r && !m) continue;
    s += (s.empty() ? "" : "; ") + scene.layers[k].name + ": ";
    s += r ? num(j.events.punctures[k].depth_m * 1e3) + " mm " + num(j.events.punctures[k].force_N, 3) + " N"
           : std::string("none");
    s += " -> ";
    s += m ? num(j.after.model_punctures[k].depth_m * 1e3) + " mm " + num(j.after.model_punctures[k].force_N, 3) + " N"
           : std::string("none");
    if (r && m)
      s += " (" + num((j.after.model_punctures[k].depth_m - j.events.punctures[k].depth_m) * 1e3, 3) + " mm, " +
           num(100.0 * (j.after.model_punctures[k].force_N / j.events.punctures[k].force_N - 1.0), 3) + " %)";
  }
  return s.empty() ? "none on either" : s;
}

double force_rmse_relative(const validation::JudgedRecording& j) {
  const validation::ObjectiveTerm* t = j.after.term("overall");
  return t && t->available ? t->value : -1.0;
}

std::string markdown(const Scene& scene, const std::vector<validation::JudgedRecording>& judged,
                     const std::vector<validation::RepeatGroup>& groups, const io::Provenance& provenance) {
  std::ostringstream s;
  s << "# " << scene.name << " against measured recordings\n\nMade by `" << provenance.command << "` ("
    << provenance.program_version << ", git " << provenance.git_revision << ", " << provenance.date_utc << ", "
    << provenance.machine << ").\n\nThe scene's model, as it is (no fitting), run on each recording's trajectory "
       "(its speed, depth, hold and withdrawal); the recording's punctures found from its force drops "
       "(validation/README.md). Force RMSE over the recording's peak force; objective: the calibration's "
       "whole-trajectory objective (sum of weight x value^2 of its terms). Curves: recording_curves.csv.\n\n"
       "| recording | speed (mm/s) | noise (N) | force RMSE / peak | objective | punctures: recording -> model "
       "(depth, force; model's error) |\n|---|---|---|---|---|---|\n";
  for (const validation::JudgedRecording& j : judged) {
    const double rmse = force_rmse_relative(j);
    s << "| " << j.reference.curve.source << " | " << num(j.speed_m_per_s * 1e3) << " | " << num(j.events.noise_N, 2)
      << " | " << (rmse >= 0.0 ? num(rmse, 3) : std::string("n/a")) << " | " << num(j.after.objective) << " | "
      << punctures_text(j, scene) << " |\n";
  }
  for (const validation::JudgedRecording& j : judged)
    if (!j.events.doubts.empty())
      s << "\n" << j.reference.curve.source << ": its punctures are a guess (" << j.events.note << ").\n";
  if (judged.size() > 1) s << validation::repeat_scatter_markdown(judged, groups, scene, {}, "scene's model");
  return s.str();
}

nlohmann::json metrics_json(const Scene& scene, const std::vector<validation::JudgedRecording>& judged,
                            const std::vector<validation::RepeatGroup>& groups, const io::Provenance& provenance) {
  nlohmann::json j{{"provenance", io::provenance_json(provenance)}, {"scene", scene.name}};
  nlohmann::json list = nlohmann::json::array();
  for (const validation::JudgedRecording& r : judged) {
    nlohmann::json layers = nlohmann::json::array();
    for (std::size_t k = 0; k < scene.layers.size(); ++k) {
      const bool rf = k < r.events.punctures.size() && r.events.punctures[k].found;
      const bool mf = k < r.after.model_punctures.size() && r.after.model_punctures[k].found;
      nlohmann::json l{{"layer", scene.layers[k].name}, {"recording_punctured", rf}, {"model_punctured", mf}};
      if (rf) l["recording"] = {{"depth_mm", r.events.punctures[k].depth_m * 1e3}, {"force_N", r.events.punctures[k].force_N}};
      if (mf)
        l["model"] = {{"depth_mm", r.after.model_punctures[k].depth_m * 1e3},
                      {"force_N", r.after.model_punctures[k].force_N}};
      layers.push_back(l);
    }
    const double rmse = force_rmse_relative(r);
    list.push_back({{"recording", r.reference.curve.source},
                    {"speed_mm_per_s", r.speed_m_per_s * 1e3},
                    {"noise_N", r.events.noise_N},
                    {"force_rmse_relative", rmse >= 0.0 ? nlohmann::json(rmse) : nlohmann::json(nullptr)},
                    {"objective", r.after.objective},
                    {"punctures_a_guess", !r.events.doubts.empty()},
                    {"layers", layers}});
  }
  j["recordings"] = list;
  nlohmann::json scatter = nlohmann::json::array();
  for (const validation::RepeatGroup& g : groups)
    if (g.members.size() >= 2)
      scatter.push_back({{"speed_mm_per_s", g.speed_m_per_s * 1e3},
                         {"recordings", g.members.size()},
                         {"repeats_rms_relative", g.repeats_rms_relative},
                         {"model_rmse_relative", g.model_rmse_relative},
                         {"model_inside_fraction", g.model_inside_fraction},
                         {"model_inside", g.model_inside}});
  j["repeat_scatter"] = scatter;
  return j;
}

}  // namespace

int validate_recordings(const ValidateOptions& options, const std::filesystem::path& scene_path, std::ostream& out) {
  if (!options.cases.empty()) throw UsageError("--reference judges the scene against recordings: not with --cases");
  if (options.refinement >= 0 || options.degree >= 0)
    throw UsageError("--refinement and --degree set the FEM reference: not with --reference (recordings)");
  const Scene scene = load_scene(scene_path);
  const std::filesystem::path dir =
      options.output_dir.empty() ? std::filesystem::path("out") / (scene.name + "_validation") : options.output_dir;
  std::vector<validation::ReferenceCurve> recordings;
  for (const std::filesystem::path& path : options.references)
    recordings.push_back(read_measured_reference(path, options.recording, scene.insertion));
  std::vector<const validation::ReferenceCurve*> all;
  for (const validation::ReferenceCurve& r : recordings) all.push_back(&r);
  require_insertion_speeds(all);
  out << "[validate] the scene's model on " << recordings.size() << " recording(s)\n";
  validation::CalibrationResult as_is;  // no fitting: the scene's own model is the one judged
  as_is.tuned_scene = scene;
  const validation::CalibrationOptions calibration;
  const std::vector<validation::JudgedRecording> judged =
      validation::judge_recordings(scene, as_is, {}, recordings, calibration);
  const std::vector<validation::RepeatGroup> groups = validation::repeat_scatter(judged);

  const io::Provenance provenance = io::make_provenance(command_line(options, scene_path, dir));
  std::vector<std::pair<std::string, const validation::InsertionCurve*>> curves;
  for (std::size_t r = 0; r < judged.size(); ++r) {
    curves.emplace_back("recording_" + std::to_string(r), &judged[r].reference.curve);
    curves.emplace_back("model_" + std::to_string(r), &judged[r].model_after);
  }
  io::OutputSession session(dir);
  session.write_text("recordings_validation.md", markdown(scene, judged, groups, provenance));
  session.write_text("recordings_validation.json", metrics_json(scene, judged, groups, provenance).dump(2) + "\n");
  session.write_text("recording_curves.csv", validation::calibration_curves_csv(curves, provenance));
  if (judged.size() > 1) session.write_text("repeat_scatter.csv", validation::repeat_scatter_csv(groups, provenance));
  session.commit();
  for (const validation::JudgedRecording& j : judged) {
    const double rmse = force_rmse_relative(j);
    out << "[validate] " << j.reference.curve.source << ": force RMSE "
        << (rmse >= 0.0 ? num(100.0 * rmse, 3) + " % of its peak" : std::string("n/a")) << "\n";
  }
  out << "[validate] report in " << dir.string() << "/recordings_validation.md\n";
  return 0;
}

}  // namespace puncture::apps
