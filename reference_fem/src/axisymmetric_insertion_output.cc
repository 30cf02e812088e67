// axisymmetric_insertion_output.cc: what the axisymmetric insertion run records (each
// step's row and its force's parts, energies, the layers' top profiles, frames), the
// checks that the records agree with the forces, and what it writes (CSV files, PVD, the
// summary JSON); the algorithm is in axisymmetric_insertion.cc.
#include "axisymmetric_insertion_run.hpp"

namespace puncture::fem::axisymmetric_insertion {

namespace {
/// Consistency of the records (check_intact_friction, check_force_drops).
constexpr double kIntactFrictionN = 0.1, kIntactFrictionShare = 0.25;
constexpr double kDropN = 0.2, kDropShare = 0.15, kDropWindow_m = 1.5e-3, kStateWindow_m = 1.0e-3;
}  // namespace

// Records a converged step: its row, every other step the pressed layer's
// surface, a frame every frame_every steps, progress every 10 steps.
void AxisymmetricInsertionRun::record_step(const std::string& phase, const StepAdvance& step) {
  const double t0 = step.t0_s, t1 = time_;
  const double velocity = phase == "dwell" ? 0.0 : (t1 > t0 ? step.advance_m / (t1 - t0) : 0.0);
  record(phase, velocity, step.cutting_N);
  const int p = pressed_layer();
  if (p >= 0 && states_[p] == LayerState::Pressed && step_index_ % 2 == 0)
    records_.add_surface_profile(step_index_, depth_, layer_top_profile(p), scene_.layers[p].name);
  if (step_index_ % frame_every_ == 0) write_frame(time_);
  if (options_.verbose && step_index_ % 10 == 0) {
    std::ostringstream m;
    m << "  step " << step_index_ << "  " << phase << "  depth " << std::fixed << std::setprecision(3)
      << depth_ * 1e3 << " mm  force " << std::setprecision(4) << rows_.back().force_N << " N (friction "
      << rows_.back().friction_N << " N)  newton " << step.newton_iterations;
    log(m.str());
  }
}

// The cutting part of the needle force over a step that advanced the tip by
// advance_m and dissipated crack_J in the cohesive layer: the crack's
// dissipation per unit advance, but no more than the needle's force beyond
// friction at the step's end. In a crack run (the cut jumps ahead at a
// puncture) the crack dissipates energy the tissue had stored, which the
// needle paid for as tip work in earlier steps; that excess is counted in
// crack_energy_released_J, so the cutting part never exceeds the needle force
// and the tip part is never pushed below zero by it.
double AxisymmetricInsertionRun::cutting_force_N(double advance_m, double crack_J) {
  if (advance_m <= 0.0) return 0.0;
  const NeedleForce f = solver_.needle_force();
  const double beyond_friction_N = f.nodes_in_contact > 0 ? std::max(0.0, f.total_N - f.friction_N) : 0.0;
  const double cutting_N = std::clamp(crack_J / advance_m, 0.0, beyond_friction_N);
  summary_.crack_energy_released_J += std::max(0.0, crack_J - cutting_N * advance_m);
  return cutting_N;
}

// The records must not contradict the forces: the shaft meets tissue only
// through a cut, so a friction force (beyond what the rounded shoulder picks
// up at the top of a crack, kIntactFriction*) while no layer is punctured
// means a cut the states missed. Stops the run (the outputs say "failed").
void AxisymmetricInsertionRun::check_intact_friction() const {
  if (std::find(states_.begin(), states_.end(), LayerState::Punctured) != states_.end()) return;
  const Row& r = rows_.back();
  if (std::abs(r.friction_N) <= std::max(kIntactFrictionN, kIntactFrictionShare * std::abs(r.force_N))) return;
  std::ostringstream m;
  m << "inconsistent puncture records at tip depth " << depth_ * 1e3 << " mm (" << r.phase << "): shaft friction "
    << r.friction_N << " N of a needle force " << r.force_N
    << " N while no layer is punctured (the shaft meets tissue only through a cut)";
  throw std::runtime_error(m.str());
}

// A large fall of the force during insertion (from a local maximum, by more
// than kDropN and kDropShare of it within kDropWindow) is a puncture: some
// layer must change state within kStateWindow of it. Stops the run otherwise.
void AxisymmetricInsertionRun::check_force_drops() const {
  std::vector<std::size_t> ins;
  for (std::size_t k = 0; k < rows_.size(); ++k)
    if (rows_[k].phase == "insertion") ins.push_back(k);
  std::vector<double> changes;
  for (std::size_t k = 1; k < rows_.size(); ++k)
    if (rows_[k].states != rows_[k - 1].states) changes.push_back(rows_[k].depth_m);
  for (std::size_t n = 0; n < ins.size(); ++n) {
    const Row& a = rows_[ins[n]];
    const bool peak = (n == 0 || a.force_N >= rows_[ins[n - 1]].force_N) &&
                      (n + 1 == ins.size() || a.force_N > rows_[ins[n + 1]].force_N);
    if (!peak) continue;
    const double limit = std::max(kDropN, kDropShare * a.force_N);
    for (std::size_t m = n + 1; m < ins.size() && rows_[ins[m]].depth_m - a.depth_m <= kDropWindow_m; ++m) {
      const Row& b = rows_[ins[m]];
      if (a.force_N - b.force_N <= limit) continue;
      const bool explained = std::any_of(changes.begin(), changes.end(), [&](double d) {
        return d >= a.depth_m - kStateWindow_m && d <= b.depth_m + kStateWindow_m;
      });
      if (explained) break;
      std::ostringstream msg;
      msg << "inconsistent puncture records: the force falls from " << a.force_N << " N at " << a.depth_m * 1e3
          << " mm to " << b.force_N << " N at " << b.depth_m * 1e3 << " mm and no layer changes state near it";
      throw std::runtime_error(msg.str());
    }
  }
}

// One row of the force-depth curve (CSV and summary): the needle force split
// into tip, cutting and friction, the tip stretch, the layer states.
void AxisymmetricInsertionRun::record(const std::string& phase, double velocity, double cutting_N) {
  const NeedleForce f = solver_.needle_force();
  const int p = pressed_layer();
  double stretch = 1.0;
  if (p >= 0 && f.nodes_in_contact > 0)
    stretch = solver_.max_principal_stretch(p, 2.0 * a_, -depth_ - 2.0 * a_, -depth_ + 2.0 * a_);
  const double total = f.nodes_in_contact > 0 ? f.total_N : 0.0;
  const double friction = f.nodes_in_contact > 0 ? f.friction_N : 0.0;
  rows_.push_back({time_, depth_, velocity, total, total - friction - cutting_N, cutting_N, friction, stretch, phase,
                   states_});
  summary_.time_s.push_back(time_);
  summary_.depth_m.push_back(depth_);
  summary_.force_N.push_back(total);
  summary_.tip_force_N.push_back(total - friction - cutting_N);
  summary_.cutting_force_N.push_back(cutting_N);
  summary_.friction_force_N.push_back(friction);
  summary_.phase.push_back(phase);
  std::vector<std::string> states;
  for (const LayerState st : states_) states.push_back(to_string(st));
  summary_.layer_states.push_back(std::move(states));
  if (total > summary_.peak_force_N) {
    summary_.peak_force_N = total;
    summary_.peak_force_depth_m = depth_;
  }
}

// Energies of the run: crack, stabilisation, and the needle's work over the
// insertion (trapezoid rule on force x depth).
void AxisymmetricInsertionRun::add_energy_totals() {
  summary_.cohesive_dissipation_J = solver_.cohesive_dissipation_J();
  summary_.stabilization_dissipation_J = solver_.stabilization_dissipation_J();
  for (std::size_t k = 1; k < rows_.size(); ++k)
    if (rows_[k].phase == "insertion")
      summary_.needle_work_J +=
          0.5 * (rows_[k].force_N + rows_[k - 1].force_N) * (rows_[k].depth_m - rows_[k - 1].depth_m);
}

// u_z(r) along the reference top of a layer.
insertion::SurfaceProfile AxisymmetricInsertionRun::layer_top_profile(std::size_t layer) const {
  return solver_.vertical_displacement_along(-scene_.layer_top_depth_m(layer));
}

// Writes one VTU frame of the meridian plane (if VTU output is asked for).
void AxisymmetricInsertionRun::write_frame(double time) {
  if (!options_.write_files || !options_.write_vtu) return;
  std::ostringstream name;
  name << "fem_fields_" << std::setw(4) << std::setfill('0') << frames_.size() << ".vtu";
  io::write_file_atomically_with(out_dir_ / name.str(),
                                 [&](const std::filesystem::path& staged) { solver_.write_vtu(staged.string()); });
  frames_.emplace_back(time, name.str());
  summary_.files_written.push_back(name.str());
}

// Writes the outputs (energies and wall time first, so the summary reports them).
void AxisymmetricInsertionRun::write_outputs(const std::string& failure) {
  add_energy_totals();
  summary_.wall_time_s = wall_timer_.wall_time();
  if (!options_.write_files) return;
  insertion::write_text_outputs(out_dir_, force_depth_csv(), records_);
  write_pvd();
  insertion::list_text_outputs(summary_.files_written);
  io::write_file_atomically(out_dir_ / "fem_summary.json", summary_json(failure).dump(2) + "\n");
}

// fem_force_depth.csv: one line per recorded row.
std::string AxisymmetricInsertionRun::force_depth_csv() const {
  std::ostringstream csv;
  csv << insertion::force_depth_header(
      "time_s,depth_mm,velocity_mm_per_s,force_N,tip_force_N,cutting_force_N,friction_force_N,tip_stretch,phase",
      scene_);
  for (const Row& r : rows_) {
    csv << format_double(r.time_s) << "," << format_double(r.depth_m * 1e3) << ","
        << format_double(r.velocity_m_per_s * 1e3) << "," << format_double(r.force_N) << ","
        << format_double(r.tip_N) << "," << format_double(r.cutting_N) << "," << format_double(r.friction_N) << ","
        << format_double(r.tip_stretch) << "," << r.phase;
    insertion::append_layer_states(csv, r.states);
    csv << "\n";
  }
  return csv.str();
}

// fem_fields.pvd: the collection of the VTU frames (if any were written),
// spelt as this reference always wrote it: no byte order, no group, times
// with 9 significant digits (format_double).
void AxisymmetricInsertionRun::write_pvd() const {
  if (frames_.empty()) return;
  std::vector<io::PvdEntry> entries;
  for (const auto& [t, name] : frames_) entries.push_back({t, 0, name});
  io::PvdFormat format;
  format.byte_order_attribute.clear();
  format.group_attribute = false;
  format.time_digits = 9;
  io::write_pvd_file(out_dir_ / "fem_fields.pvd", entries, nullptr, format);
  summary_.files_written.push_back("fem_fields.pvd");
}

// fem_summary.json: the model, the peak, the energies, the counts, the
// timings, the punctures and the files.
nlohmann::json AxisymmetricInsertionRun::summary_json(const std::string& failure) const {
  nlohmann::json j = insertion::common_summary_json(failure.empty() ? "ok" : "failed", scene_.name, summary_, degree_,
                                                    refinement_, scene_.fem.load_step_m, /*with_stretch=*/false);
  if (!failure.empty()) j["error"] = failure;
  j.update({{"geometry", "axisymmetric"},
            {"assembly_threads", summary_.assembly_threads},
            {"n_ranks_used", 1},
            {"tip_element_size_mm", mesh_.tip_element_size_m * 1e3},
            {"crack_radius_mm", mesh_.crack_radius_m * 1e3},
            {"elements_through_layer", mesh_.elements_through_layer},
            {"cohesive_dissipation_J", summary_.cohesive_dissipation_J},
            {"crack_energy_released_J", summary_.crack_energy_released_J},
            {"stabilization_dissipation_J", summary_.stabilization_dissipation_J},
            {"needle_work_insertion_J", summary_.needle_work_J},
            {"steps_accepted_at_stall", summary_.steps_accepted_at_stall},
            {"steps_accepted_last_resort", summary_.steps_accepted_last_resort},
            {"largest_accepted_residual_N", summary_.largest_accepted_residual_N},
            {"steps_continued", summary_.steps_continued}});
  return j;
}

}  // namespace puncture::fem::axisymmetric_insertion
