// fem_comparison.cpp: see fem_comparison.hpp.
#include "puncture/validation/fem_comparison.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "puncture/io/atomic_file.hpp"
#include "puncture/io/csv_reader.hpp"
#include "puncture/io/csv_writer.hpp"
#include "puncture/validation/number_format.hpp"
#include "puncture/validation/recording.hpp"

namespace puncture::validation {

namespace {

constexpr double kMm = 1e-3;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Appends (r, uz) to the profile, keeping r strictly increasing.
void append_point(RadialProfile& p, double r_m, double uz_m) {
  if (!p.r_m.empty() && r_m <= p.r_m.back()) return;
  p.r_m.push_back(r_m);
  p.uz_m.push_back(uz_m);
}

/// The FEM profile at `depth`: linear in depth between the two recorded
/// profiles that bracket it when they share their radii (the same surface
/// nodes), else the nearest one.
RadialProfile fem_profile_at_depth(std::vector<RadialProfile> profiles, double depth) {
  std::sort(profiles.begin(), profiles.end(), [](const auto& a, const auto& b) { return a.depth_m < b.depth_m; });
  for (std::size_t i = 0; i + 1 < profiles.size(); ++i) {
    const RadialProfile& a = profiles[i];
    const RadialProfile& b = profiles[i + 1];
    if (a.depth_m <= depth && depth <= b.depth_m && b.depth_m > a.depth_m && a.r_m == b.r_m) {
      const double t = (depth - a.depth_m) / (b.depth_m - a.depth_m);
      RadialProfile p = a;
      p.depth_m = depth;
      for (std::size_t j = 0; j < p.uz_m.size(); ++j) p.uz_m[j] = (1 - t) * a.uz_m[j] + t * b.uz_m[j];
      return p;
    }
  }
  return profile_nearest_depth(profiles, depth);
}

}  // namespace

FemResultFiles read_fem_result(const std::filesystem::path& dir, const Scene& scene) {
  FemResultFiles fem;
  fem.curve = read_insertion_curve(dir / "fem_force_depth.csv");
  fem.summary = nlohmann::json::parse(io::read_text_file(dir / "fem_summary.json"));
  if (fem.summary.contains("punctures"))
    for (const auto& p : fem.summary["punctures"])
      fem.puncture_depth_m[p.at("name").get<std::string>()] = p.at("depth_mm").get<double>() * kMm;

  {  // surface profiles, one per (step, surface)
    const io::CsvDocument doc = io::read_csv_file(dir / "fem_surface_profile.csv");
    const std::size_t c_surface = doc.require_column("surface"), c_step = doc.require_column("step"),
                      c_depth = doc.require_column("depth_mm"), c_r = doc.require_column("r_mm"),
                      c_uz = doc.require_column("uz_mm");
    for (const io::CsvRecord& row : doc.records) {
      const std::string& surface = row.fields[c_surface];
      const int step = static_cast<int>(doc.number(row, c_step));
      auto& list = fem.profiles[surface];
      if (list.empty() || list.back().step != step) {
        RadialProfile p;
        p.step = step;
        p.depth_m = doc.number(row, c_depth) * kMm;
        list.push_back(p);
      }
      append_point(list.back(), doc.number(row, c_r) * kMm, doc.number(row, c_uz) * kMm);
    }
  }
  {  // spring-back profiles
    const io::CsvDocument doc = io::read_csv_file(dir / "fem_recovery_profile.csv");
    const std::size_t c_layer = doc.require_column("layer"), c_phase = doc.require_column("phase"),
                      c_depth = doc.require_column("depth_mm"), c_r = doc.require_column("r_mm"),
                      c_uz = doc.require_column("uz_mm");
    for (const io::CsvRecord& row : doc.records) {
      const double layer_value = doc.number(row, c_layer);
      const int layer = static_cast<int>(layer_value);
      if (layer < 0 || layer >= static_cast<int>(scene.layers.size()) || layer != layer_value)
        throw io::CsvFormatError(doc.source, row.line, "layer", "layer index out of range");
      const std::string& name = scene.layers[static_cast<std::size_t>(layer)].name;
      auto& target = row.fields[c_phase] == "before" ? fem.before_breakthrough[name] : fem.after_breakthrough[name];
      target.depth_m = doc.number(row, c_depth) * kMm;
      append_point(target, doc.number(row, c_r) * kMm, doc.number(row, c_uz) * kMm);
    }
  }
  const auto pvd = dir / "fem_fields.pvd";
  if (std::filesystem::is_regular_file(pvd)) {
    const std::string text = io::read_text_file(pvd);
    const std::regex dataset(R"re(<DataSet[^>]*timestep="([^"]+)"[^>]*file="([^"]+)")re");
    const std::regex source(R"re(Source="([^"]+)")re");
    for (auto it = std::sregex_iterator(text.begin(), text.end(), dataset); it != std::sregex_iterator(); ++it) {
      FemFrame f;
      if (!io::parse_finite_number((*it)[1], f.time_s))
        throw std::runtime_error(pvd.string() + ": timestep is not a finite number: '" + std::string((*it)[1]) + "'");
      f.pvtu = (*it)[2];
      f.files.push_back(f.pvtu);
      const std::filesystem::path pvtu_dir = std::filesystem::path(f.pvtu).parent_path();
      const std::string pvtu_text = io::read_text_file(dir / f.pvtu);
      for (auto s = std::sregex_iterator(pvtu_text.begin(), pvtu_text.end(), source); s != std::sregex_iterator(); ++s)
        f.files.push_back((pvtu_dir / std::string((*s)[1])).string());
      fem.frame_times_s.push_back(f.time_s);
      fem.frames.push_back(std::move(f));
    }
  }
  return fem;
}

double fem_deflection_at_mm(const FemResultFiles& fem, const Scene& scene, std::size_t layer, double r_m,
                            double time_s) {
  const auto it = fem.profiles.find(scene.layers[layer].name);
  if (it == fem.profiles.end() || it->second.empty()) return kNaN;
  const double depth = scene.insertion.speed_m_per_s * time_s - scene.insertion.start_height_m;
  const RadialProfile& p = profile_nearest_depth(it->second, depth);
  if (std::abs(p.depth_m - depth) > 0.5 * scene.fem.load_step_m + 1e-9) return kNaN;
  double uz = kNaN;
  if (!interpolate_linear(p.r_m, p.uz_m, r_m, uz)) return kNaN;
  return -uz / kMm;
}

RingRecorder::RingRecorder(const Scene& scene) {
  for (const Layer& l : scene.layers) {
    offset_.push_back(stride_);
    const int w = scene.effects.surface_force ? l.force_mesh.rings_w : 0;
    rings_per_layer_.push_back(w);
    stride_ += static_cast<std::size_t>(w);
  }
}

void RingRecorder::record(const PunctureSimulator& sim) {
  const std::size_t base = data_.size();
  data_.resize(base + stride_, 0.0);
  std::vector<int> count;
  for (std::size_t k = 0; k < sim.layer_count() && k < rings_per_layer_.size(); ++k) {
    const Eigen::Matrix3Xd& pos = sim.node_positions(k);
    const Eigen::Matrix3Xd& rest = sim.node_rest_positions(k);
    const std::vector<int>& ring = sim.node_rings(k);
    const int w = rings_per_layer_[k];
    if (pos.cols() == 0 || w == 0) continue;
    count.assign(static_cast<std::size_t>(w), 0);
    double* out = data_.data() + base + offset_[k];
    for (Eigen::Index i = 0; i < pos.cols(); ++i) {
      const int j = ring[static_cast<std::size_t>(i)] - 1;
      if (j < 0 || j >= w) continue;
      out[j] += -(pos(2, i) - rest(2, i));
      ++count[static_cast<std::size_t>(j)];
    }
    for (int j = 0; j < w; ++j)
      if (count[static_cast<std::size_t>(j)] > 0) out[j] /= count[static_cast<std::size_t>(j)];
  }
  ++ticks_;
}

std::vector<double> RingRecorder::rings(std::size_t tick, std::size_t layer) const {
  if (tick >= ticks_ || layer >= rings_per_layer_.size()) throw std::out_of_range("RingRecorder::rings");
  const double* begin = data_.data() + tick * stride_ + offset_[layer];
  return std::vector<double>(begin, begin + rings_per_layer_[layer]);
}

LayerDeflectionComparison compare_layer_deflection(const Scene& scene, std::size_t k, const ScriptedRunResult& run,
                                                   const RingRecorder& recorder, const FemResultFiles& fem) {
  LayerDeflectionComparison c;
  const Layer& layer = scene.layers[k];
  const double L = layer.force_mesh.spacing_L_m;
  if (!scene.effects.surface_force || recorder.ticks() != run.ticks.size() || run.ticks.empty()) return c;

  // Insertion phase of the real-time run: up to the deepest tick.
  std::size_t deepest = 0;
  for (std::size_t i = 0; i < run.ticks.size(); ++i)
    if (run.ticks[i].depth_m > run.ticks[deepest].depth_m) deepest = i;
  std::size_t broke = run.ticks.size();
  for (std::size_t i = 0; i < run.ticks.size(); ++i)
    if (run.ticks[i].layers[k].state == LayerState::Punctured) {
      broke = i;
      break;
    }
  const double realtime_pre_depth =
      broke < run.ticks.size() && broke > 0 ? run.ticks[broke - 1].depth_m : run.ticks[deepest].depth_m;

  std::vector<RadialProfile> candidates;
  if (const auto it = fem.profiles.find(layer.name); it != fem.profiles.end()) candidates = it->second;
  if (const auto it = fem.before_breakthrough.find(layer.name); it != fem.before_breakthrough.end())
    candidates.push_back(it->second);
  const auto fem_break = fem.puncture_depth_m.find(layer.name);
  const double fem_break_depth =
      fem_break == fem.puncture_depth_m.end() ? std::numeric_limits<double>::infinity() : fem_break->second;

  if (!candidates.empty()) {
    const double compare_depth = std::min(realtime_pre_depth, fem_break_depth);
    std::size_t tick = run.ticks.size();
    for (std::size_t i = 0; i <= deepest && i < broke; ++i)
      if (run.ticks[i].velocity_m_per_s > 0.0 && run.ticks[i].depth_m <= compare_depth + 1e-12) tick = i;
    if (tick < run.ticks.size()) {
      c.realtime_depth_m = run.ticks[tick].depth_m;
      c.realtime_rings_m = recorder.rings(tick, k);
      c.fem = fem_profile_at_depth(candidates, c.realtime_depth_m);
      c.fem_depth_m = c.fem.depth_m;
      c.error = deflection_profile_error(c.realtime_rings_m, L, c.fem);
      c.compared = c.error.n_rings > 0;
    }
  }

  const auto after = fem.after_breakthrough.find(layer.name);
  if (after != fem.after_breakthrough.end() && broke < run.ticks.size()) {
    const auto delay_ticks =
        static_cast<std::size_t>(std::ceil(layer.resumption_time_s * scene.realtime.haptic_rate_Hz - 1e-9));
    std::size_t tick = std::min(run.ticks.size() - 1, broke + delay_ticks);
    // The FEM's profile after the break is taken before the next layer breaks
    // (at the break's load step or the next): so is this one, if the next
    // layer breaks within the resumption time (fast insertions).
    if (k + 1 < scene.layers.size())
      for (std::size_t i = broke + 1; i <= tick; ++i)
        if (run.ticks[i].layers[k + 1].state == LayerState::Punctured) {
          tick = i - 1;
          break;
        }
    c.recovery_delay_s = run.ticks[tick].time_s - run.ticks[broke].time_s;
    c.recovery_realtime_depth_m = run.ticks[tick].depth_m;
    c.realtime_recovered_rings_m = recorder.rings(tick, k);
    c.fem_after = after->second;
    c.recovery_error = deflection_profile_error(c.realtime_recovered_rings_m, L, c.fem_after);
    c.recovery_compared = c.recovery_error.n_rings > 0;
  }
  return c;
}

std::vector<std::string> run_plot_script(const std::string& script, const std::filesystem::path& dir,
                                         std::ostream& out, std::ostream& err) {
  std::filesystem::path path = std::filesystem::path(PUNCTURE_SOURCE_DIR) / "scripts" / script;
  if (!std::filesystem::exists(path)) path = std::filesystem::path("scripts") / script;
  const std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  if (!std::filesystem::exists(path)) {
    err << "warning: " << script << " not found: no PNG plots\n";
  } else {
    const std::string log = (dir / ".plot.log").string();
    const std::string command = python + " '" + path.string() + "' '" + dir.string() + "' > '" + log + "' 2>&1";
    const int status = std::system(command.c_str());
    if (status != 0) {
      err << "warning: plotting failed (" << command << "):\n";
      std::ifstream in(log);
      err << in.rdbuf();
    } else {
      out << "[plot] " << script << " done\n";
    }
    std::error_code ignored;
    std::filesystem::remove(log, ignored);
  }
  std::vector<std::string> pngs;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".png") pngs.push_back(e.path().filename().string());
  std::sort(pngs.begin(), pngs.end());
  return pngs;
}

namespace {
std::string num(double x, int precision = 4) {
  if (!std::isfinite(x)) return "–";
  return significant_digits(x, precision);
}
std::string num(const nlohmann::json& j, const char* key, double scale = 1.0, int precision = 4) {
  if (!j.contains(key) || !j[key].is_number()) return "–";
  return num(j[key].get<double>() * scale, precision);
}
}  // namespace

namespace {

/// The summary's provenance section.
void provenance_section(std::ostringstream& md, const Scene& scene, const io::Provenance& provenance,
                        const FemReferenceInfo& reference, const FemResultFiles& fem) {
  md << "## Provenance\n\n";
  md << "- command: `" << provenance.command << "`\n";
  md << "- program " << provenance.program_version << ", git revision " << provenance.git_revision << "\n";
  md << "- machine: " << provenance.machine << "\n";
  md << "- date (UTC): " << provenance.date_utc << "\n";
  md << "- scene: `" << scene.source_path << "`\n";
  md << "- FEM reference: key `" << reference.hash << "` (" << (reference.from_cache ? "from the cache" : "computed")
     << "), " << fem.summary.value("n_dofs", 0) << " DoFs, Q" << fem.summary.value("element_degree", 0)
     << ", refinement " << fem.summary.value("refinement", 0) << ", " << fem.summary.value("load_steps", 0)
     << " load steps, " << num(fem.summary.value("wall_time_s", 0.0), 3) << " s wall time\n";
  md << "- real-time model: SH degree " << scene.realtime.sh_degree << ", integrator " << scene.realtime.integrator
     << ", haptic rate " << num(scene.realtime.haptic_rate_Hz) << " Hz\n\n";

}

/// The summary's force table per layer.
void force_section(std::ostringstream& md, const CurveComparison& cmp, const nlohmann::json& layers) {
  md << "## Force against depth\n\n";
  md << "Force RMSE over the compared insertion (" << num(cmp.compared_from_depth_m / kMm) << " to "
     << num(cmp.compared_to_depth_m / kMm) << " mm, " << cmp.n_compared << " FEM samples): **"
     << num(cmp.force_rmse_N) << " N**, " << num(100 * cmp.force_rmse_relative, 3) << " % of the FEM peak "
     << num(cmp.reference_peak_force_N) << " N. The real-time force compared is its whole force, the damping "
        "force d h v of the punctured layers included (as `puncture run` and the app render it; the FEM is "
        "quasi-static, so d h v has no separate counterpart there and is judged with the friction).\n\n";
  md << "| layer | pressing force RMSE (N) | pressing RMSE / FEM peak | FEM puncture depth (mm) | real-time puncture depth (mm) | "
        "depth error (mm) | force error (N) | deflection RMSE before breakthrough (mm) | max error (mm) | "
        "recovery RMSE (mm) |\n";
  md << "|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& j : layers) {
    const std::string name = j["layer"].get<std::string>();
    const LayerMetrics* m = cmp.layer(name);
    md << "| " << name << " | " << num(j, "pressing_force_rmse_N") << " | " << num(j, "pressing_force_rmse_relative") << " | "
       << (m && m->reference_puncture.found ? num(m->reference_puncture.depth_m / kMm) : "not punctured") << " | "
       << (m && m->model_puncture.found ? num(m->model_puncture.depth_m / kMm) : "not punctured") << " | "
       << num(j, "puncture_depth_error_mm") << " | " << num(j, "puncture_force_error_N") << " | "
       << (j.contains("deflection") ? num(j["deflection"], "rmse_mm") : "–") << " | "
       << (j.contains("deflection") ? num(j["deflection"], "max_abs_error_mm") : "–") << " | "
       << (j.contains("recovery") ? num(j["recovery"], "rmse_mm") : "–") << " |\n";
  }
  md << "\nThe pressing force RMSE is over the layer's pressed interval (from its contact to its puncture) only; "
        "the acceptance below judges the pressing and the cut together. Depth and force errors are real-time "
        "minus FEM. The deflection is compared at the last depth at which "
        "the layer is intact in both models: ring deflections Delta Z_j at r = (j - 1) L against the FEM's -u_z "
        "of the layer's top surface at the same distance from the needle. The recovery compares the FEM's "
        "spring-back (same depth, after the material along the needle path was removed) with the real-time "
        "ring deflections one resumption time (the layer's resumption_time_s, rounded up to haptic steps) after its breakthrough, "
        "or at the last tick before the next layer breaks if that comes first (the FEM's profile after a break is taken "
        "before the next layer breaks).\n\n";
}

/// The summary's list of files.
void files_section(std::ostringstream& md, const Scene& scene, bool has_vtk) {
  md << "## Files\n\n";
  md << "| file | content |\n|---|---|\n";
  md << "| [force_depth_aligned.csv](force_depth_aligned.csv) | FEM insertion samples with the real-time force at "
        "the same depths |\n";
  md << "| [realtime_curve.csv](realtime_curve.csv) | real-time curve (every haptic tick, per-layer states) |\n";
  md << "| [fem_force_depth.csv](fem_force_depth.csv) | FEM curve (every load step, per-layer states) |\n";
  md << "| [layer_metrics.csv](layer_metrics.csv) | per-layer metrics (the table above, full precision) |\n";
  md << "| [deflection_profiles.csv](deflection_profiles.csv) | deflection against r, both models, before and "
        "after breakthrough |\n";
  md << "| [fem_recovery_profile.csv](fem_recovery_profile.csv) | FEM spring-back profiles |\n";
  md << "| [validation_metrics.json](validation_metrics.json) | all metrics, FEM summary, provenance |\n";
  if (has_vtk)
    md << "| [validation.pvd](validation.pvd) | ParaView: open this one file. Part 0: FEM fields (`fem/*.vtu`) "
          "at x = 0; the real-time layer surfaces and force meshes (`realtime/*.vtp`) stand beside it, shifted by "
          "one sample diameter (" << num(scene.sample.diameter_m / kMm) << " mm) in +x, with point fields "
          "`deflection_mm` and `deflection_error_mm` (real-time minus FEM at the same r and depth) |\n";
}

}  // namespace

std::string validation_summary_markdown(const Scene& scene, const io::Provenance& provenance,
                                        const FemReferenceInfo& reference, const FemResultFiles& fem,
                                        const CurveComparison& cmp, const nlohmann::json& layers,
                                        const std::vector<std::string>& plots, bool has_vtk,
                                        const std::string& acceptance_section) {
  std::ostringstream md;
  md << "# Validation: " << scene.name << "\n\n";
  md << "Real-time SHF + MSM model against the deal.II FEM reference on the identical insertion ("
     << num(scene.insertion.speed_m_per_s / kMm) << " mm/s to " << num(scene.insertion.target_depth_m / kMm)
     << " mm), aligned on depth (withdrawal on depth, dwell on the time since it began). The table below is the "
        "insertion per layer; the acceptance section compares the whole trajectory.\n\n";
  provenance_section(md, scene, provenance, reference, fem);
  force_section(md, cmp, layers);
  if (!acceptance_section.empty()) {
    md << "## Acceptance per layer (whole trajectory)\n\n"
          "A layer is accepted when its force RMSE over pressing and cut is at most 10 % of the FEM peak, "
          "its puncture depth within the layer's force-mesh spacing L of the FEM's, its puncture force within "
          "10 % of the FEM's (the FEM's punctures from its state columns), and its surface's deflection RMSE at "
          "most 15 % of the FEM's largest deflection before its breakthrough and 25 % after it (the comparison "
          "above).\n\n"
       << acceptance_section << "\n";
  }

  if (!plots.empty()) {
    md << "## Plots\n\n";
    for (const std::string& p : plots) md << "![" << p << "](" << p << ")\n\n";
  }
  files_section(md, scene, has_vtk);
  return md.str();
}

std::string layer_metrics_csv(const Scene& scene, const CurveComparison& cmp,
                              const std::vector<LayerDeflectionComparison>& defl, const io::Provenance& provenance) {
  io::CsvWriter csv({"layer", "pressed_from_mm", "pressed_to_mm", "n_samples", "pressing_force_rmse_N",
                     "pressing_force_rmse_relative",
                     "fem_puncture_depth_mm", "realtime_puncture_depth_mm", "puncture_depth_error_mm",
                     "fem_puncture_force_N", "realtime_puncture_force_N", "puncture_force_error_N",
                     "deflection_realtime_depth_mm", "deflection_fem_depth_mm", "deflection_rings", "deflection_rmse_mm",
                     "deflection_max_error_mm", "deflection_relative_rmse", "recovery_delay_s", "recovery_rings",
                     "recovery_rmse_mm", "recovery_max_error_mm"});
  csv.add_provenance(provenance);
  auto value = [&](bool ok, double x) { csv.number(ok ? x : kNaN, 10); };
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const LayerMetrics* m = cmp.layer(scene.layers[k].name);
    const LayerDeflectionComparison& d = defl[k];
    csv.text(scene.layers[k].name);
    if (m) {
      const bool both = m->reference_puncture.found && m->model_puncture.found;
      value(m->has_pressed_interval, m->pressed_from_depth_m / kMm);
      value(m->has_pressed_interval, m->pressed_to_depth_m / kMm);
      csv.integer(static_cast<long long>(m->n_samples));
      value(true, m->force_rmse_N);
      value(true, m->force_rmse_relative);
      value(m->reference_puncture.found, m->reference_puncture.depth_m / kMm);
      value(m->model_puncture.found, m->model_puncture.depth_m / kMm);
      value(both, m->puncture_depth_error_m / kMm);
      value(m->reference_puncture.found, m->reference_puncture.force_N);
      value(m->model_puncture.found, m->model_puncture.force_N);
      value(both, m->puncture_force_error_N);
    } else {
      value(false, 0), value(false, 0);
      csv.integer(0);
      for (int i = 0; i < 8; ++i) value(false, 0);
    }
    value(true, d.realtime_depth_m / kMm);
    value(true, d.fem_depth_m / kMm);
    csv.integer(static_cast<long long>(d.error.n_rings));
    value(d.compared, d.error.rmse_m / kMm);
    value(d.compared, d.error.max_abs_error_m / kMm);
    value(d.compared, d.error.relative_rmse);
    value(true, d.recovery_delay_s);
    csv.integer(static_cast<long long>(d.recovery_error.n_rings));
    value(d.recovery_compared, d.recovery_error.rmse_m / kMm);
    value(d.recovery_compared, d.recovery_error.max_abs_error_m / kMm);
    csv.end_row();
  }
  return csv.str();
}

std::string deflection_profiles_csv(const Scene& scene, const std::vector<LayerDeflectionComparison>& defl,
                                    const io::Provenance& provenance) {
  io::CsvWriter csv({"layer", "phase", "model", "depth_mm", "r_mm", "deflection_mm"});
  csv.add_provenance(provenance);
  auto rings = [&](const std::string& layer, const char* phase, double depth, const std::vector<double>& dz,
                   double L) {
    for (std::size_t j = 0; j < dz.size(); ++j)
      csv.text(layer).text(phase).text("realtime").number(depth / kMm, 10)
          .number(static_cast<double>(j) * L / kMm, 10).number(dz[j] / kMm, 10).end_row();
  };
  auto fem = [&](const std::string& layer, const char* phase, const RadialProfile& p) {
    for (std::size_t i = 0; i < p.r_m.size(); ++i)
      csv.text(layer).text(phase).text("fem").number(p.depth_m / kMm, 10).number(p.r_m[i] / kMm, 10)
          .number(-p.uz_m[i] / kMm, 10).end_row();
  };
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const std::string& name = scene.layers[k].name;
    const double L = scene.layers[k].force_mesh.spacing_L_m;
    const LayerDeflectionComparison& d = defl[k];
    if (d.compared) {
      rings(name, "before_breakthrough", d.realtime_depth_m, d.realtime_rings_m, L);
      fem(name, "before_breakthrough", d.fem);
    }
    if (d.recovery_compared) {
      rings(name, "after_breakthrough", d.recovery_realtime_depth_m, d.realtime_recovered_rings_m, L);
      fem(name, "after_breakthrough", d.fem_after);
    }
  }
  return csv.str();
}

std::string aligned_curves_csv(const InsertionCurve& realtime, const InsertionCurve& fem,
                               const io::Provenance& provenance) {
  io::CsvWriter csv({"depth_mm", "fem_force_N", "realtime_force_N", "difference_N"});
  csv.add_provenance(provenance);
  const std::vector<std::size_t> rt_idx = insertion_phase(realtime);
  std::vector<double> rt_depth, rt_force;
  for (std::size_t i : rt_idx) rt_depth.push_back(realtime.depth_m[i]), rt_force.push_back(realtime.force_N[i]);
  for (std::size_t i : insertion_phase(fem)) {
    double f = kNaN;
    const bool inside = interpolate_linear(rt_depth, rt_force, fem.depth_m[i], f);
    csv.number(fem.depth_m[i] / kMm, 10).number(fem.force_N[i], 10).number(inside ? f : kNaN, 10)
        .number(inside ? f - fem.force_N[i] : kNaN, 10).end_row();
  }
  return csv.str();
}

nlohmann::json layer_metrics_json(const Scene& scene, const CurveComparison& cmp,
                                  const std::vector<LayerDeflectionComparison>& defl) {
  nlohmann::json layers = nlohmann::json::array();
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    nlohmann::json j;
    j["layer"] = scene.layers[k].name;
    if (const LayerMetrics* m = cmp.layer(scene.layers[k].name)) {
      j["pressing_force_rmse_N"] = m->force_rmse_N;
      j["pressing_force_rmse_relative"] = m->force_rmse_relative;
      j["n_samples"] = m->n_samples;
      j["fem_punctured"] = m->reference_puncture.found;
      j["realtime_punctured"] = m->model_puncture.found;
      if (m->reference_puncture.found && m->model_puncture.found) {
        j["puncture_depth_error_mm"] = m->puncture_depth_error_m / kMm;
        j["puncture_force_error_N"] = m->puncture_force_error_N;
      }
    }
    if (defl[k].compared)
      j["deflection"] = {{"realtime_depth_mm", defl[k].realtime_depth_m / kMm},
                         {"fem_depth_mm", defl[k].fem_depth_m / kMm},
                         {"rings", defl[k].error.n_rings},
                         {"rmse_mm", defl[k].error.rmse_m / kMm},
                         {"max_abs_error_mm", defl[k].error.max_abs_error_m / kMm},
                         {"relative_rmse", defl[k].error.relative_rmse}};
    if (defl[k].recovery_compared)
      j["recovery"] = {{"delay_s", defl[k].recovery_delay_s},
                       {"rings", defl[k].recovery_error.n_rings},
                       {"rmse_mm", defl[k].recovery_error.rmse_m / kMm},
                       {"max_abs_error_mm", defl[k].recovery_error.max_abs_error_m / kMm}};
    layers.push_back(j);
  }
  return layers;
}

}  // namespace puncture::validation
