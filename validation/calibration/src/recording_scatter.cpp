// recording_scatter.cpp: see recording_scatter.hpp.
#include "puncture/validation/recording_scatter.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "model_runs.hpp"
#include "puncture/io/csv_writer.hpp"
#include "puncture/validation/number_format.hpp"

namespace puncture::validation {

namespace {

std::string num(double x, int precision = 4) { return significant_digits(x, precision); }

/// The recording's insertion force (linear between its insertion samples, clamped at their ends).
class InsertionForce {
 public:
  explicit InsertionForce(const InsertionCurve& c) {
    for (std::size_t i : insertion_phase(c)) {
      depth_.push_back(c.depth_m[i]);
      force_.push_back(c.force_N[i]);
    }
  }
  double deepest() const { return depth_.back(); }
  double at(double d) const {
    const auto it = std::lower_bound(depth_.begin(), depth_.end(), d);
    if (it == depth_.begin()) return force_.front();
    if (it == depth_.end()) return force_.back();
    const std::size_t i = static_cast<std::size_t>(it - depth_.begin());
    const double span = depth_[i] - depth_[i - 1];
    if (!(span > 0.0)) return force_[i];
    const double t = (d - depth_[i - 1]) / span;
    return force_[i - 1] + t * (force_[i] - force_[i - 1]);
  }

 private:
  std::vector<double> depth_, force_;
};

/// Groups of recordings by speed (each within the tolerance of its group's slowest).
std::vector<std::vector<std::size_t>> speed_groups(const std::vector<JudgedRecording>& recordings, double tolerance) {
  std::vector<std::size_t> order(recordings.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return recordings[a].speed_m_per_s < recordings[b].speed_m_per_s;
  });
  std::vector<std::vector<std::size_t>> groups;
  double first = 0.0;
  for (std::size_t i : order) {
    const double v = recordings[i].speed_m_per_s;
    if (groups.empty() || v > first * (1.0 + tolerance)) {
      groups.push_back({});
      first = v;
    }
    groups.back().push_back(i);
  }
  return groups;
}

/// Per layer: the members' punctures beside the model's (the group's first member's run).
std::vector<LayerScatter> layer_scatter(const std::vector<JudgedRecording>& recordings, const RepeatGroup& g) {
  std::vector<LayerScatter> out;
  const JudgedRecording& first = recordings[g.members.front()];
  const std::size_t n_layers = first.events.punctures.size();
  for (std::size_t k = 0; k < n_layers; ++k) {
    std::vector<double> force, depth;
    for (std::size_t m : g.members) {
      const auto& p = recordings[m].events.punctures;
      if (k < p.size() && p[k].found) {
        force.push_back(p[k].force_N);
        depth.push_back(p[k].depth_m);
      }
    }
    if (force.empty()) continue;
    LayerScatter s;
    s.layer = k;
    s.force_N = spread_of(force);
    s.depth_m = spread_of(depth);
    const auto& model = first.after.model_punctures;
    s.model_found = k < model.size() && model[k].found;
    if (s.model_found) {
      s.model_force_N = model[k].force_N;
      s.model_depth_m = model[k].depth_m;
      s.force_inside = s.model_force_N >= s.force_N.min && s.model_force_N <= s.force_N.max;
      s.depth_inside = s.model_depth_m >= s.depth_m.min && s.model_depth_m <= s.depth_m.max;
    }
    out.push_back(s);
  }
  return out;
}

/// The band of the members' insertion forces and the model's place in it.
void curve_band(const std::vector<JudgedRecording>& recordings, RepeatGroup& g, const RepeatScatterOptions& o) {
  std::vector<InsertionForce> members;
  double deepest = std::numeric_limits<double>::infinity();
  for (std::size_t m : g.members) {
    members.emplace_back(recordings[m].reference.curve);
    deepest = std::min(deepest, members.back().deepest());
  }
  const InsertionForce model(recordings[g.members.front()].model_after);
  if (!(deepest > 0.0) || o.grid_points < 2) return;
  double width = 0.0, model_sq = 0.0, repeats_sq = 0.0;
  int inside = 0;
  for (int i = 0; i < o.grid_points; ++i) {
    const double d = deepest * i / (o.grid_points - 1);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo, sum = 0.0;
    std::vector<double> f;
    for (const InsertionForce& m : members) f.push_back(m.at(d));
    for (double x : f) lo = std::min(lo, x), hi = std::max(hi, x), sum += x;
    const double mean = sum / f.size(), fm = model.at(d);
    for (double x : f) repeats_sq += (x - mean) * (x - mean);
    g.depth_m.push_back(d), g.band_min_N.push_back(lo), g.band_max_N.push_back(hi);
    g.mean_N.push_back(mean), g.model_N.push_back(fm);
    width += hi - lo;
    model_sq += (fm - mean) * (fm - mean);
    if (fm >= lo && fm <= hi) ++inside;
    g.peak_N = std::max(g.peak_N, std::abs(mean));
  }
  const double n = o.grid_points;
  g.band_width_N = width / n;
  g.model_inside_fraction = inside / n;
  const double peak = g.peak_N > 0.0 ? g.peak_N : 1.0;
  g.model_rmse_relative = std::sqrt(model_sq / n) / peak;
  g.repeats_rms_relative = std::sqrt(repeats_sq / (n * members.size())) / peak;
  g.model_inside = g.model_inside_fraction >= o.inside_fraction;
}

const char* yes_no(bool b) { return b ? "yes" : "**no**"; }

std::string range_text(const Spread& s, double scale, int digits = 3) {
  return num(s.mean * scale, digits) + " +- " + num(s.sd * scale, 2) + " [" + num(s.min * scale, digits) + ", " +
         num(s.max * scale, digits) + "]";
}

}  // namespace

Spread spread_of(const std::vector<double>& values) {
  Spread s;
  s.n = values.size();
  if (values.empty()) return s;
  s.min = *std::min_element(values.begin(), values.end());
  s.max = *std::max_element(values.begin(), values.end());
  double sum = 0.0;
  for (double v : values) sum += v;
  s.mean = sum / values.size();
  double sq = 0.0;
  for (double v : values) sq += (v - s.mean) * (v - s.mean);
  s.sd = values.size() > 1 ? std::sqrt(sq / (values.size() - 1)) : 0.0;
  return s;
}

std::vector<JudgedRecording> judge_recordings(const Scene& start, const CalibrationResult& result,
                                              const std::vector<ReferenceCurve>& fitted,
                                              const std::vector<ReferenceCurve>& held_out,
                                              const CalibrationOptions& options) {
  std::vector<JudgedRecording> out;
  for (std::size_t r = 0; r < fitted.size() && r < result.model_after.size(); ++r) {
    JudgedRecording j;
    j.reference = fitted[r];
    j.speed_m_per_s = calibration_detail::reference_speed(start, fitted[r].curve);
    j.events = result.reference_events[r];
    j.model_before = result.model_before[r], j.model_after = result.model_after[r];
    j.before = result.trajectory_before[r], j.after = result.trajectory_after[r];
    out.push_back(std::move(j));
  }
  if (held_out.empty()) return out;
  const std::vector<LayerGeometry> geometry = layer_geometry(start);
  const SurfaceCache cache(start);
  for (const ReferenceCurve& ref : held_out) {
    JudgedRecording j;
    j.reference = ref;
    j.held_out = true;
    j.speed_m_per_s = calibration_detail::reference_speed(start, ref.curve);
    j.events = reference_events(ref.curve, geometry, {}, options.detection);
    j.model_before = simulate_insertion_curve(calibration_run_scene(start, ref, options), &cache);
    j.model_after = simulate_insertion_curve(calibration_run_scene(result.tuned_scene, ref, options), &cache);
    j.before = compare_trajectory(j.model_before, ref.curve, j.events, geometry, options.weights);
    j.after = compare_trajectory(j.model_after, ref.curve, j.events, geometry, options.weights);
    out.push_back(std::move(j));
  }
  return out;
}

std::vector<RepeatGroup> repeat_scatter(const std::vector<JudgedRecording>& recordings, const RepeatScatterOptions& o) {
  std::vector<RepeatGroup> groups;
  for (const std::vector<std::size_t>& members : speed_groups(recordings, o.speed_tolerance)) {
    RepeatGroup g;
    g.members = members;
    for (std::size_t m : members) g.speed_m_per_s += recordings[m].speed_m_per_s / members.size();
    g.layers = layer_scatter(recordings, g);
    if (members.size() >= 2) curve_band(recordings, g, o);
    groups.push_back(std::move(g));
  }
  return groups;
}

std::string recordings_markdown(const std::vector<JudgedRecording>& recordings, const Scene& scene) {
  std::ostringstream s;
  s << "\n## Recordings\n\nEvery recording, with the model before and after run on its trajectory (its speed, depth, "
       "hold and withdrawal). Fitted ones are the calibration's objective; held-out ones were left out of the fit "
       "and are judged with the tuned model only (their punctures from their force drops). Objective: the sum of "
       "weight x value^2 of every term over the whole trajectory; force RMSE over the recording's peak.\n\n"
       "| recording | use | speed (mm/s) | objective before | after | force RMSE after | punctures: recording -> "
       "model after (mm, N) |\n|---|---|---|---|---|---|---|\n";
  for (const JudgedRecording& j : recordings) {
    const ObjectiveTerm* rmse = j.after.term("overall");
    s << "| " << j.reference.curve.source << " | " << (j.held_out ? "**held out**" : "fitted") << " | "
      << num(j.speed_m_per_s * 1e3) << " | " << num(j.before.objective) << " | " << num(j.after.objective) << " | "
      << (rmse && rmse->available ? num(rmse->value, 3) : std::string("n/a")) << " | ";
    for (std::size_t k = 0; k < j.events.punctures.size() && k < scene.layers.size(); ++k) {
      const auto& p = j.events.punctures[k];
      const bool m = k < j.after.model_punctures.size() && j.after.model_punctures[k].found;
      s << (k ? "; " : "") << scene.layers[k].name << ": "
        << (p.found ? num(p.depth_m * 1e3) + " mm " + num(p.force_N, 3) + " N" : std::string("none")) << " -> "
        << (m ? num(j.after.model_punctures[k].depth_m * 1e3) + " mm " + num(j.after.model_punctures[k].force_N, 3) +
                    " N"
              : std::string("none"));
    }
    s << " |\n";
  }
  for (const JudgedRecording& j : recordings)
    if (j.held_out && !j.events.doubts.empty())
      s << "\nHeld-out " << j.reference.curve.source << ": its punctures are a guess (" << j.events.note << ").\n";
  return s.str();
}

std::string repeat_scatter_markdown(const std::vector<JudgedRecording>& recordings,
                                    const std::vector<RepeatGroup>& groups, const Scene& scene,
                                    const RepeatScatterOptions& o, const std::string& model_label) {
  std::ostringstream s;
  s << "\n## Scatter of repeats\n\nRecordings whose insertion speeds lie within " << num(o.speed_tolerance * 100, 3)
    << " % of each other are repeats of one condition. Per condition: each layer's puncture force and depth as "
       "mean +- SD [min, max] over the repeats beside the " << model_label << "'s, and the band of the repeats' insertion "
       "forces (pointwise min to max on " << o.grid_points << " depths from contact to the shallowest repeat's "
       "deepest sample; it holds the sensor noise too) with the model's place in it: the model sits inside when it "
       "lies in the band at >= " << num(o.inside_fraction * 100, 3) << " % of those depths. Band: repeat_scatter.csv.\n";
  for (const RepeatGroup& g : groups) {
    s << "\n### " << num(g.speed_m_per_s * 1e3) << " mm/s: " << g.members.size() << " recording(s)\n\n";
    for (std::size_t m : g.members)
      s << "- " << recordings[m].reference.curve.source << (recordings[m].held_out ? " (held out)" : " (fitted)")
        << ", noise " << num(recordings[m].events.noise_N, 2) << " N\n";
    if (g.members.size() < 2) {
      s << "\nOne recording: no scatter to judge the model against.\n";
      continue;
    }
    s << "\n| layer | puncture force (N) | model (N) | inside | puncture depth (mm) | model (mm) | inside "
         "|\n|---|---|---|---|---|---|---|\n";
    for (const LayerScatter& l : g.layers) {
      const std::string name = l.layer < scene.layers.size() ? scene.layers[l.layer].name : std::to_string(l.layer);
      s << "| " << name << " (" << l.force_N.n << " of " << g.members.size() << ") | " << range_text(l.force_N, 1.0)
        << " | " << (l.model_found ? num(l.model_force_N, 3) : "none") << " | " << yes_no(l.force_inside) << " | "
        << range_text(l.depth_m, 1e3) << " | " << (l.model_found ? num(l.model_depth_m * 1e3) : "none") << " | "
        << yes_no(l.depth_inside) << " |\n";
    }
    s << "\nCurve band: mean width " << num(g.band_width_N, 3) << " N (" << num(100 * g.band_width_N / std::max(g.peak_N, 1e-300), 3)
      << " % of the repeats' mean peak " << num(g.peak_N, 3) << " N); the repeats scatter about their mean by "
      << num(100 * g.repeats_rms_relative, 3) << " % of that peak (RMS); the model's RMSE from their mean is "
      << num(100 * g.model_rmse_relative, 3) << " %; the model lies in the band at "
      << num(100 * g.model_inside_fraction, 3) << " % of the depths: "
      << (g.model_inside ? "it sits inside the scatter." : "**it does not sit inside the scatter.**") << "\n";
  }
  return s.str();
}

std::string repeat_scatter_csv(const std::vector<RepeatGroup>& groups, const io::Provenance& provenance) {
  io::CsvWriter csv({"group", "speed_mm_per_s", "depth_mm", "band_min_N", "band_max_N", "mean_N", "model_N"});
  csv.add_provenance(provenance);
  for (std::size_t gi = 0; gi < groups.size(); ++gi) {
    const RepeatGroup& g = groups[gi];
    for (std::size_t i = 0; i < g.depth_m.size(); ++i)
      csv.integer(static_cast<long long>(gi))
          .number(g.speed_m_per_s * 1e3, 6)
          .number(g.depth_m[i] * 1e3, 6)
          .number(g.band_min_N[i], 6)
          .number(g.band_max_N[i], 6)
          .number(g.mean_N[i], 6)
          .number(g.model_N[i], 6)
          .end_row();
  }
  return csv.str();
}

}  // namespace puncture::validation
