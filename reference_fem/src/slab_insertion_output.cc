// slab_insertion_output.cc: what the 3D reference's insertion run records (each load step,
// the punctures, the surface profiles) and writes (force-depth CSV, summary JSON, VTU frames);
// the algorithm is in slab_insertion_run.cc.
#include "slab_insertion_run.hpp"

namespace puncture::fem::slab_insertion {

// The puncture event at its peak, its row and the surface before breakthrough.
PunctureEvent SlabInsertionRun::record_before_puncture(std::size_t layer, double force, double stretch) {
  PunctureEvent event;
  event.layer = int(layer);
  event.layer_name = scene_.layers[layer].name;
  event.depth_m = depth_;
  event.force_N = force;
  event.max_stretch = stretch;
  event.time_s = (depth_ + start_height_) / (speed_ * path_.axis_cosine);
  record_row(depth_, force, stretch, needle_force_vector().lateral_N);
  records_.add_recovery_profile(layer, "before", depth_, surface_profile(layer));
  return event;
}

// After the spring-back: the force on the next layer (if touched), the
// surface after breakthrough, the event, its row and a frame.
void SlabInsertionRun::record_after_puncture(std::size_t layer, PunctureEvent event) {
  const bool touching = any_contact();
  const NeedleForce after = touching ? needle_force_vector() : NeedleForce{};
  event.force_after_N = after.axial_N;
  if (current_layer_ < n_layers_ && touching) states_[current_layer_] = LayerState::Pressed;
  records_.add_recovery_profile(layer, "after", depth_, surface_profile(layer));
  summary_.punctures.push_back(event);
  log("  PUNCTURE of " + event.layer_name + " at depth " + format_double(depth_ * 1e3, 5) + " mm, force " +
      format_double(event.force_N, 5) + " N -> " + format_double(event.force_after_N, 5) + " N");
  const double stretch_after = current_layer_ < n_layers_ && touching ? tip_stretch(current_layer_) : 1.0;
  record_row(depth_, event.force_after_N, stretch_after, after.lateral_N);
  write_frame(depth_);
}

// The end of a load step: its row, the pressed surface, a frame every
// vtu_stride steps (and the last), a progress line.
void SlabInsertionRun::record_load_step(int step) {
  const bool touching = any_contact();
  const NeedleForce force_vector = touching ? needle_force_vector() : NeedleForce{};
  const double force = force_vector.axial_N;
  const double stretch = touching && current_layer_ < n_layers_ ? tip_stretch(current_layer_) : 1.0;
  if (!std::isfinite(force) || !std::isfinite(force_vector.lateral_N))
    throw std::runtime_error("fem: non-finite needle force");
  // (A puncture at the end of the step already recorded this depth.)
  if (!(rows_.back().depth_m == depth_ && rows_.back().force_N == force))
    record_row(depth_, force, stretch, force_vector.lateral_N);
  ++record_index_;
  if (current_layer_ < n_layers_)
    records_.add_surface_profile(record_index_, depth_, surface_profile(current_layer_),
                                 scene_.layers[current_layer_].name);
  if (step % vtu_stride_ == 0 || step == n_steps_) write_frame(depth_);
  std::ostringstream s;
  s << "  step " << std::setw(4) << step << "/" << n_steps_ << "  depth " << std::fixed << std::setprecision(3)
    << depth_ * 1e3 << " mm  force " << std::setprecision(5) << force << " N  tip stretch "
    << std::setprecision(4) << stretch << "  contact " << contact_.size() << "  newton(total) "
    << summary_.newton_iterations;
  log(s.str());
}

// u_z(r) of a layer's top interface, averaged over nodes at the same r (rank 0 gets it).
insertion::SurfaceProfile SlabInsertionRun::surface_profile(std::size_t layer) const {
  std::vector<std::pair<double, double>> local;
  const IndexSet owned = solver_.dof_handler().locally_owned_dofs();
  for (const std::size_t n : interface_nodes_[layer])
    if (owned.is_element(nodes_[n].dof[2])) local.emplace_back(nodes_[n].r(), u_of(nodes_[n], 2));
  const auto all = Utilities::MPI::gather(comm_, local, 0);
  std::map<long long, std::pair<double, int>> by_r;
  std::map<long long, double> r_of;
  for (const auto& part : all)
    for (const auto& [r, uz] : part) {
      const long long key = std::llround(r / (1e-7 * thickness_));
      auto& acc = by_r[key];
      acc.first += uz;
      acc.second += 1;
      r_of[key] = r;
    }
  insertion::SurfaceProfile profile;
  for (const auto& [key, acc] : by_r) profile.emplace_back(r_of[key], acc.first / acc.second);
  return profile;
}

// One row of the force-depth curve (CSV and summary).
void SlabInsertionRun::record_row(double depth, double force, double stretch, double lateral_force) {
  const double time = (depth + start_height_) / (speed_ * path_.axis_cosine);  // vertical depth at v cos a
  rows_.push_back({time, depth, speed_, force, stretch, states_, lateral_force});
  summary_.time_s.push_back(time);
  summary_.depth_m.push_back(depth);
  summary_.force_N.push_back(force);
  if (force > summary_.peak_force_N) {
    summary_.peak_force_N = force;
    summary_.peak_force_depth_m = depth;
  }
}

// Writes one frame of the fields (collective; if VTU output is asked for).
void SlabInsertionRun::write_frame(double depth) {
  if (!fields_) return;
  const auto names = fields_->write_frame(solver_, (depth + start_height_) / (speed_ * path_.axis_cosine));
  if (root_) summary_.files_written.insert(summary_.files_written.end(), names.begin(), names.end());
}

// Writes the PVD collection, then (rank 0) the CSV files, the Newton log and
// the summary with `status` ("completed" or "failed") and `error`.
void SlabInsertionRun::write_outputs(const std::string& status, const std::string& error) {
  if (!options_.write_files) return;
  if (fields_ && root_) summary_.files_written.push_back(fields_->write_collection());
  else if (fields_) fields_->write_collection();
  if (!root_) return;
  insertion::write_text_outputs(out_dir_, force_depth_csv(), records_);
  insertion::list_text_outputs(summary_.files_written);
  summary_.wall_time_s = wall_timer_.wall_time();
  io::write_file_atomically(out_dir_ / "fem_summary.json", summary_json(status, error).dump(2) + "\n");
}

// fem_force_depth.csv: one line per recorded row; an inclined needle's run
// adds the tip's depth along the needle and the force across it. (The time
// runs with the vertical depth, which the tip covers at v cos a.)
std::string SlabInsertionRun::force_depth_csv() const {
  const bool inclined = scene_.insertion.angle_deg != 0.0;
  std::ostringstream csv;
  csv << insertion::force_depth_header(inclined ? "time_s,depth_mm,velocity_mm_per_s,force_N,tip_stretch,path_depth_mm,"
                                                  "lateral_force_N"
                                                : "time_s,depth_mm,velocity_mm_per_s,force_N,tip_stretch",
                                       scene_);
  for (const auto& r : rows_) {
    csv << format_double(r.time_s) << "," << format_double(r.depth_m * 1e3) << ","
        << format_double(r.velocity_m_per_s * 1e3) << "," << format_double(r.force_N) << ","
        << format_double(r.tip_stretch, 6);
    if (inclined) csv << "," << format_double(r.depth_m / path_.axis_cosine * 1e3) << "," << format_double(r.lateral_force_N);
    insertion::append_layer_states(csv, r.states);
    csv << "\n";
  }
  return csv.str();
}

// fem_summary.json: the model, the peak, the counts, the timings, the
// punctures and the files.
nlohmann::json SlabInsertionRun::summary_json(const std::string& status, const std::string& error) const {
  nlohmann::json j = insertion::common_summary_json(status, scene_.name, summary_, disc_.degree, disc_.refinement,
                                                    load_step_, /*with_stretch=*/true);
  if (!error.empty()) j["error"] = error;
  j.update({{"n_ranks", summary_.n_ranks},
            {"formulation", options_.formulation},
            {"final_depth_mm", final_depth_ * 1e3},
            {"note", "quasi-static; the FEM stops at the target depth (no dwell, no withdrawal)"},
            {"puncture_bisections", summary_.bisections},
            {"spring_back_stages", summary_.spring_back_stages},
            {"puncture_depth_resolution_mm", resolution_ * 1e3},
            {"linear_iterations", summary_.linear_iterations}});
  return j;
}

}  // namespace puncture::fem::slab_insertion
