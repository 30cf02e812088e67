// The objective of one calibration stage (stage_objective.hpp).
#include "stage_objective.hpp"

#include <algorithm>
#include <cmath>

#include "model_runs.hpp"

namespace puncture::validation::calibration_detail {

StageObjective::StageObjective(const StageObjective& other)
    : scene(other.scene),
      parameters(other.parameters),
      selection(other.selection),
      with_dwell(other.with_dwell),
      turn_depth_m(other.turn_depth_m),
      in_(other.in_),
      name_(other.name_),
      layout_(other.layout_),
      evaluations_(other.evaluations_),
      best_(other.best_),
      best_x_(other.best_x_) {}

namespace {

/// True if the model run has not punctured a selected layer that the
/// reference punctures within the compared depths: a run that turned before
/// its breakthrough, repeated over the whole trajectory.
bool misses_a_reference_puncture(const TrajectoryComparison& c, const ReferenceEvents& ev, const TermSelection& sel) {
  for (std::size_t k = 0; k < ev.punctures.size() && k < c.model_punctures.size(); ++k) {
    const bool selected = sel.layers.empty() || std::find(sel.layers.begin(), sel.layers.end(), k) != sel.layers.end();
    if (selected && ev.punctures[k].found && ev.punctures[k].depth_m <= sel.max_depth_m && !c.model_punctures[k].found)
      return true;
  }
  return false;
}

}  // namespace

Scene StageObjective::scene_at(const double* x) const {
  Scene s = scene;
  for (std::size_t p = 0; p < parameters.size(); ++p) set_param(s, parameters[p], parameters[p].value_of(x[p]));
  return s;
}

std::vector<TrajectoryComparison> StageObjective::compare(const Scene& s) const {
  std::vector<TrajectoryComparison> out;
  const std::vector<ReferenceCurve>& refs = *in_.references;
  for (std::size_t r = 0; r < refs.size(); ++r) {
    auto run_to = [&](double turn_m) {
      const InsertionCurve model = simulate_insertion_curve(objective_scene(s, refs[r], *in_.options, with_dwell, turn_m),
                                                            in_.cache);
      return compare_trajectory(model, refs[r].curve, (*in_.events)[r], *in_.geometry, in_.options->weights,
                                selection[r]);
    };
    TrajectoryComparison c = run_to(turn_depth_m);
    if (std::isfinite(turn_depth_m) && misses_a_reference_puncture(c, (*in_.events)[r], selection[r]))
      c = run_to(std::numeric_limits<double>::infinity());
    out.push_back(std::move(c));
  }
  return out;
}

double StageObjective::value_of(const Scene& s) const {
  double total = 0.0;
  for (const TrajectoryComparison& c : compare(s)) total += c.objective;
  return std::isfinite(total) ? total : kFailedObjective;
}

double StageObjective::evaluate(const double* x) {
  if (stopped()) return kFailedObjective;
  double f = kFailedObjective;
  try {
    f = value_of(scene_at(x));
  } catch (const std::exception&) {
    f = kFailedObjective;  // e.g. a candidate the simulator rejects: counted, never accepted
  }
  record(x, f);
  return f;
}

void StageObjective::record(const double* x, double f) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++evaluations_;
  if (in_.total_evaluations) ++*in_.total_evaluations;
  const std::vector<double> candidate(x, x + parameters.size());
  if (better(f, candidate)) {
    best_ = f;
    best_x_ = candidate;
  }
  if (in_.progress && *in_.progress && !stopped()) {
    try {
      (*in_.progress)(CalibrationProgress{in_.total_evaluations ? *in_.total_evaluations : evaluations_, best_, f, name_});
    } catch (...) {
      if (!in_.stop) throw;
      in_.stop->capture(std::current_exception());
    }
  }
}

void StageObjective::offer(const std::vector<double>& x, double f) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (better(f, x)) best_ = f, best_x_ = x;
}

bool StageObjective::better(double f, const std::vector<double>& x) const {
  // Equal objectives (a parameter the objective does not see) are decided by
  // the smaller x, not by which thread recorded first: the best point does
  // not depend on the order of parallel evaluations.
  return f < best_ || (f == best_ && !best_x_.empty() && x < best_x_);
}

bool StageObjective::set_layout(const std::vector<double>& x) {
  if (stopped()) return false;
  std::vector<TrajectoryComparison> cs;
  try {
    cs = compare(scene_at(x.data()));
  } catch (const std::exception&) {
    return false;
  }
  layout_.clear();
  for (const TrajectoryComparison& c : cs) {
    layout_.emplace_back();
    for (const ObjectiveTerm& t : c.terms) layout_.back().emplace_back(t.label(), t.residuals.size());
  }
  return true;
}

bool StageObjective::residuals_at(const std::vector<double>& x, std::vector<double>& r) {
  r.clear();
  if (stopped()) return false;
  std::vector<TrajectoryComparison> cs;
  double total = 0.0;
  try {
    cs = compare(scene_at(x.data()));
  } catch (const std::exception&) {
    record(x.data(), kFailedObjective);
    return false;
  }
  for (std::size_t k = 0; k < cs.size() && k < layout_.size(); ++k) {
    total += cs[k].objective;
    for (const auto& [label, count] : layout_[k]) {
      const ObjectiveTerm* t = nullptr;
      for (const ObjectiveTerm& candidate : cs[k].terms)
        if (candidate.label() == label) t = &candidate;
      const std::size_t at = r.size();
      r.resize(at + count, 0.0);
      if (!t || count == 0) continue;
      if (t->residuals.size() == count) std::copy(t->residuals.begin(), t->residuals.end(), r.begin() + static_cast<long>(at));
      else r[at] = std::sqrt(t->contribution());
    }
  }
  const bool ok = std::isfinite(total) && cs.size() == layout_.size();
  record(x.data(), ok ? total : kFailedObjective);
  return ok;
}

}  // namespace puncture::validation::calibration_detail
