// axisymmetric_insertion.cc: the needle insertion in the meridian plane (see
// needle_insertion.hpp and reference_fem/README.md). run_axisymmetric_insertion
// reads top-down as the algorithm: build the mesh and the solver
// (AxisymmetricInsertionRun's constructor), then walk the needle along the
// scene's trajectory (approach, insertion, dwell, withdrawal) and, at every
// step, advance the needle (cutting the step when Newton fails), detect
// punctures (the layer states, the crack opened), record the row, the
// profiles and the frames; then write the outputs. Runs on rank 0; the other
// ranks receive the outcome.
#include <deal.II/base/mpi.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

#ifdef __linux__
#include <sched.h>
#include <unistd.h>
#endif

#include <puncture/fem/axisymmetric_solver.hpp>
#include <puncture/fem/cpu_affinity.hpp>
#include <puncture/fem/field_output.hpp>
#include <puncture/fem/needle_insertion.hpp>
#include <puncture/io/pvd.hpp>
#include <puncture/meshing/axisymmetric_slab_mesh.hpp>

#include "insertion_common.hpp"
#include "axisymmetric_insertion_run.hpp"

namespace puncture::fem {

namespace {

using insertion::format_double;
using insertion::LayerState;
using axisymmetric_insertion::LayerLaws;
using axisymmetric_insertion::TrajectoryPoint;

constexpr double kPi = 3.14159265358979323846;
/// The share of the needle's opening within which a layer's cohesive law
/// must be able to separate its faces fully (separable_strength_Pa).
constexpr double kSeparableOpeningShare = 0.9;

/// The cohesive strength (Pa) with which the needle can separate a crack's
/// faces: the scene's sigma_c, raised to 2 G_c / (0.9 x the needle's opening)
/// where the law's full separation 2 G_c / sigma_c would exceed that. The
/// needle's opening is the largest separation it imposes on the crack: the
/// ring's radial opening from r_c to the shaft times the law's opening scale
/// (2a for a bevel: the slit's faces spread over its width; a - r_lumen for a
/// hollow tip). A law that needs more than the needle opens would leave its
/// faces holding on to the shaft behind the tip with a residual traction: a
/// crack the needle has passed but never separated (no puncture recorded
/// while the force shows one) and a grip that multiplies the shaft friction.
/// The raised strength keeps G_c, so the work to cut a unit area and the
/// steady cutting force G_c x 2a are the scene's.
double separable_strength_Pa(const LayerCrack& crack, double radial_opening_m) {
  const double opening = crack.opening_scale * radial_opening_m;
  if (!(opening > 0.0)) return crack.law.strength_Pa;  // a flat punch shears its crack open without bound
  return std::max(crack.law.strength_Pa, 2.0 * crack.law.toughness_J_per_m2 / (kSeparableOpeningShare * opening));
}

/// The scene's trajectory as the list of step end points: the approach to the
/// surface in one step, insertion in steps of load_step, the dwell in steps
/// that start at an insertion step's duration and double (a relaxation is
/// fast at first, slow later), withdrawal in steps of twice the load step back
/// to the start height.
std::vector<TrajectoryPoint> trajectory(const Scene& scene, double stop_depth_m) {
  const Insertion& in = scene.insertion;
  const double step = scene.fem.load_step_m;
  const double target = stop_depth_m > 0.0 ? std::min(stop_depth_m, in.target_depth_m) : in.target_depth_m;
  std::vector<TrajectoryPoint> out;
  double t = in.start_height_m / in.speed_m_per_s;
  out.push_back({t, 0.0, "approach"});
  const int n_in = static_cast<int>(std::ceil(target / step - 1e-9));
  for (int k = 1; k <= n_in; ++k) {
    const double d = std::min(k * step, target);
    out.push_back({t + d / in.speed_m_per_s, d, "insertion"});
  }
  t += target / in.speed_m_per_s;
  if (stop_depth_m > 0.0) return out;  // a study stops at this depth
  if (in.dwell_s > 0.0) {
    double held = 0.0, dt = step / in.speed_m_per_s;
    while (held < in.dwell_s) {
      // Never leave a last sliver shorter than half a step.
      held = held + 1.5 * dt >= in.dwell_s ? in.dwell_s : held + dt;
      out.push_back({t + held, target, "dwell"});
      dt *= 2.0;
    }
    t += in.dwell_s;
  }
  const double w_step = 2.0 * step, end = -in.start_height_m;
  const int n_out = static_cast<int>(std::ceil((target - end) / w_step - 1e-9));
  for (int k = 1; k <= n_out; ++k) {
    const double d = std::max(target - k * w_step, end);
    out.push_back({t + (target - d) / in.withdrawal_speed_m_per_s, d, "withdrawal"});
  }
  return out;
}

LayerLaws layer_laws(const Scene& scene, double crack_radius_m) {
  LayerLaws laws;
  const bool bevel = scene.needle.tip == "bevel";
  const double a = scene.needle.radius_m;
  for (const Layer& l : scene.layers) {
    laws.materials.push_back(insertion::long_term_material(l.material));
    laws.prony.push_back(insertion::prony_terms(l.material.viscoelastic));
    LayerCrack c;
    if (l.puncture.kind == PunctureCriterion::Kind::FractureEnergy) {
      c.kind = LayerCrack::Kind::Cohesive;
      c.law.strength_Pa = l.puncture.cohesive_strength_Pa;
      c.law.toughness_J_per_m2 = l.puncture.toughness_J_per_m2;
      c.law.viscosity_s = scene.fem.cohesive_viscosity_s;
      if (bevel) {
        c.area_scale = 2.0 * a / (2.0 * kPi * crack_radius_m);
        c.opening_scale = 2.0 * a / (a - crack_radius_m);
      }
      c.law.strength_Pa = separable_strength_Pa(c, a - crack_radius_m);
    } else {
      c.kind = LayerCrack::Kind::TiedUntilBroken;
    }
    laws.cracks.push_back(c);
    laws.friction.push_back({l.shaft_friction.dynamic_coefficient, l.shaft_friction.static_coefficient});
  }
  return laws;
}

/// Newton settings of the axisymmetric solver from the scene.
AxisymmetricSettings solver_settings(const Scene& scene, int degree) {
  AxisymmetricSettings settings;
  settings.degree = static_cast<unsigned>(degree);
  settings.max_newton_iterations = scene.fem.max_newton_iterations;
  settings.newton_tolerance = scene.fem.newton_tolerance;
  settings.verbose = std::getenv("PUNCTURE_FEM_DEBUG") != nullptr;
  settings.stabilization_time_s = scene.fem.stabilization_time_s;
  // Rank 0 solves while the other ranks sleep (share_outcome), so its cell
  // loop may use every core; PUNCTURE_FEM_THREADS overrides.
  settings.assembly_threads = std::max(1u, std::thread::hardware_concurrency());
  if (const char* t = std::getenv("PUNCTURE_FEM_THREADS")) settings.assembly_threads = std::max(1, std::atoi(t));
  return settings;
}

/// The scene checks of this reference; returns the element degree (1 or 2).
int checked_element_degree(const Scene& scene, const FemRunOptions& options) {
  insertion::check_axial_insertion(scene);
  const int degree = insertion::element_degree(scene, options);
  if (degree != 1 && degree != 2) throw std::invalid_argument("fem: element degree must be 1 or 2");
  return degree;
}

}  // namespace

namespace axisymmetric_insertion {

constexpr double kMinStepFraction = 1.0 / 256.0;
/// A step cut to this fraction of the planned one that still fails plain
/// Newton is continued (pseudo-transient continuation) before it is cut again.
constexpr double kContinuationFraction = 1.0 / 64.0;
/// A Newton stall is accepted below this share of the run's largest needle
/// force so far (the needle force is then exact to about that share): the
/// kinks of contact, friction and damage where Newton cycles at millinewtons.
constexpr double kStallAcceptanceOfPeak = 1e-3;
/// The last resort before a run stops: a step at 1/256 of the planned one
/// that neither Newton nor continuation brings below the floor above is solved
/// once more accepting a stall below this share of the peak (half the 1 %
/// the reference is held to). Where Coulomb friction holds a node on the
/// crack line between stick and slip (withdrawal through the skin) Newton
/// cycles at a few millinewtons; each such step is counted
/// (steps_accepted_last_resort) and its residual reported.
constexpr double kLastResortStallOfPeak = 5e-3;
/// A crack point is open (cut) at this damage.
constexpr double kCutDamage = 0.999;

AxisymmetricInsertionRun::AxisymmetricInsertionRun(const Scene& scene, const FemRunOptions& options, MPI_Comm comm,
                                                   FemRunSummary& summary)
    : scene_(scene),
      options_(options),
      summary_(summary),
      degree_(checked_element_degree(scene, options)),
      refinement_(insertion::refinement_level(scene, options)),
      cutting_(scene.needle.tip != "blunt"),
      n_layers_(scene.layers.size()),
      a_(scene.needle.radius_m),
      mesh_(meshing::build_axisymmetric_slab_mesh(scene, refinement_)),
      laws_(layer_laws(scene, mesh_.crack_radius_m)),
      solver_(mesh_, laws_.materials, laws_.cracks, laws_.friction, solver_settings(scene, degree_)),
      out_dir_(options.output_dir),
      plan_(trajectory(scene, options.stop_depth_m)),
      frame_every_(std::max<int>(1, static_cast<int>(plan_.size()) / std::max(1, options.max_vtu_frames))),
      states_(n_layers_, LayerState::Untouched),
      peak_force_(n_layers_, 0.0),
      peak_depth_(n_layers_, 0.0),
      peak_time_(n_layers_, 0.0),
      peak_profile_(n_layers_),
      depth_(-scene.insertion.start_height_m) {
  solver_.set_viscoelasticity(laws_.prony);
  solver_.setup(0.5 * scene.sample.diameter_m, scene.total_thickness_m());
  describe_model(comm);
  if (options.write_files) std::filesystem::create_directories(out_dir_);
}

// Fills the model part of the summary, warns about a coarse mesh, logs the model.
void AxisymmetricInsertionRun::describe_model(MPI_Comm comm) {
  summary_.geometry = "axisymmetric";
  summary_.n_dofs = solver_.n_dofs();
  summary_.assembly_threads = static_cast<int>(solver_.settings().assembly_threads);
  summary_.n_cells = solver_.n_cells();
  summary_.n_ranks = static_cast<int>(dealii::Utilities::MPI::n_mpi_processes(comm));
  summary_.degree = degree_;
  summary_.refinement = refinement_;
  summary_.tip_element_size_m = mesh_.tip_element_size_m;
  summary_.elements_through_layer = mesh_.elements_through_layer;
  // Resolution the mesh-convergence study of this model found within 3 % of
  // the extrapolated needle force before the skin punctures
  // (results/fem_axisymmetric_convergence.md): Q1 from 4 elements per needle
  // radius (worst 1.95 %); Q2, whose nodal contact converges from below, from
  // 16 (Q2 with 8: -4.4 % at 0.5 mm).
  const double per_radius = a_ / mesh_.tip_element_size_m;
  const double needed = degree_ == 1 ? 4.0 : 16.0;
  if (per_radius < needed - 1e-9)
    summary_.warnings.push_back("mesh: " + format_double(per_radius, 3) + " elements per needle radius with Q" +
                                std::to_string(degree_) + "; at least " + format_double(needed, 2) +
                                " are needed for the needle force to be within 3 % of its converged value "
                                "(results/fem_axisymmetric_convergence.md)");
  for (std::size_t i = 0; i < n_layers_; ++i) {
    const PunctureCriterion& p = scene_.layers[i].puncture;
    const double strength = laws_.cracks[i].law.strength_Pa;
    if (p.kind == PunctureCriterion::Kind::FractureEnergy && strength > p.cohesive_strength_Pa * (1.0 + 1e-12))
      summary_.warnings.push_back(
          "layer '" + scene_.layers[i].name + "': cohesive strength raised from " +
          format_double(p.cohesive_strength_Pa * 1e-3, 4) + " to " + format_double(strength * 1e-3, 4) +
          " kPa (G_c kept): with the scene's, 2 G_c / sigma_c = " +
          format_double(2e3 * p.toughness_J_per_m2 / p.cohesive_strength_Pa, 3) +
          " mm exceeds what the needle can open, and the crack it passes would never separate");
  }
  for (std::size_t i = 0; i < n_layers_; ++i)
    if (mesh_.elements_through_layer[i] < 4)
      summary_.warnings.push_back("mesh: layer '" + scene_.layers[i].name + "' has only " +
                                  std::to_string(mesh_.elements_through_layer[i]) + " elements through its thickness");
  std::ostringstream s;
  s << "fem: scene '" << scene_.name << "', axisymmetric, " << summary_.n_cells << " cells, Q" << degree_ << " ("
    << summary_.n_dofs << " dofs), tip element " << mesh_.tip_element_size_m * 1e3 << " mm, needle tip '"
    << scene_.needle.tip << "', crack radius " << mesh_.crack_radius_m * 1e3 << " mm, "
    << summary_.assembly_threads << " assembly thread(s)";
  log(s.str());
  for (const auto& w : summary_.warnings) std::cerr << "warning: " << w << std::endl;
}

// The algorithm: at every point of the trajectory, advance the needle (cut
// the step while Newton fails), detect punctures, record; then the energies.
void AxisymmetricInsertionRun::walk_trajectory() {
  record("approach", scene_.insertion.speed_m_per_s, 0.0);
  write_frame(time_);
  for (std::size_t k = 0; k < plan_.size(); ++k) {
    const TrajectoryPoint& goal = plan_[k];
    const std::string phase = goal.phase;
    if (phase == "approach") {  // nothing touches the tissue above its surface
      depth_ = goal.depth_m;
      time_ = goal.time_s;
      record(phase, scene_.insertion.speed_m_per_s, 0.0);
      continue;
    }
    while (time_ < goal.time_s - 1e-12 * std::max(1.0, goal.time_s)) {
      const std::optional<StepAdvance> step = advance_needle(k);
      if (!step) continue;  // the step was cut: try again with half of it
      detect_punctures();
      record_step(phase, *step);
      check_intact_friction();
      if (options_.on_step) options_.on_step(depth_, plan_.back().time_s > 0.0 ? time_ / plan_.back().time_s : 1.0);
    }
  }
  check_force_drops();
}

// Moves the tip one (sub-)step toward plan point k and solves; a failed solve
// cuts the step (nothing returned), a converged one advances the state.
std::optional<StepAdvance> AxisymmetricInsertionRun::advance_needle(std::size_t k) {
  const TrajectoryPoint& goal = plan_[k];
  const TrajectoryPoint& from = plan_[k - 1];
  const double t0 = time_, d0 = depth_;
  const double t1 = std::min(goal.time_s, t0 + fraction_ * (goal.time_s - from.time_s));
  // Sub-steps of a planned step follow the trajectory linearly.
  const double s = (t1 - from.time_s) / (goal.time_s - from.time_s);
  const double d1 = from.depth_m + s * (goal.depth_m - from.depth_m);
  place_needle(d1);
  solver_.set_time_step(t1 - t0);
  solver_.set_stall_acceptance_floor((last_resort_ ? kLastResortStallOfPeak : kStallAcceptanceOfPeak) *
                                     summary_.peak_force_N);
  const double advance = d1 - d0;
  const double predictor = (last_advance_ != 0.0 && advance * last_advance_ > 0.0) ? advance / last_advance_ : 0.0;
  const double dissipated_before = solver_.cohesive_dissipation_J();
  const dealii::Timer solve_timer;
  const AxisymmetricNewtonReport report = solver_.solve_step(predictor, fraction_ <= kContinuationFraction);
  summary_.solve_time_s += solve_timer.wall_time();
  summary_.newton_iterations += report.iterations;
  records_.newton_log << "step " << step_index_ << "  " << goal.phase << "  depth " << d1 * 1e3 << " mm  t " << t1
                      << " s\n";
  for (const auto& line : report.table) records_.newton_log << line << "\n";
  if (!report.converged) {
    cut_step(report, goal.phase, d0, d1);
    return std::nullopt;
  }
  ++step_index_;
  ++summary_.load_steps;
  if (report.accepted_at_stall) {
    ++summary_.steps_accepted_at_stall;
    summary_.largest_accepted_residual_N = std::max(summary_.largest_accepted_residual_N, report.residual_N);
  }
  if (last_resort_) ++summary_.steps_accepted_last_resort;
  last_resort_ = false;
  if (report.continuation_steps > 0) ++summary_.steps_continued;
  time_ = t1;
  depth_ = d1;
  last_advance_ = advance;
  fraction_ = std::min(1.0, 2.0 * fraction_);
  return StepAdvance{t0, advance, cutting_force_N(advance, solver_.cohesive_dissipation_J() - dissipated_before),
                     report.iterations};
}

// A failed step: halve it (stop with an error below 1/256 of the planned
// step) and put the needle back where it was.
void AxisymmetricInsertionRun::cut_step(const AxisymmetricNewtonReport& report, const std::string& phase, double d0,
                                        double d1) {
  ++summary_.step_cuts;
  records_.newton_log << "  -> " << report.failure << "; step cut\n";
  fraction_ *= 0.5;
  if (fraction_ < kMinStepFraction && !last_resort_) {
    last_resort_ = true;
    fraction_ = kMinStepFraction;
    records_.newton_log << "  -> last resort: the step again, accepting a stall below "
                        << kLastResortStallOfPeak * summary_.peak_force_N << " N\n";
  }
  if (fraction_ < kMinStepFraction) {
    std::ostringstream m;
    m << "no convergence at tip depth " << d1 * 1e3 << " mm (" << phase
      << ") even with 1/256 of the load step and a stall accepted below " << 100.0 * kLastResortStallOfPeak
      << " % of the peak force: " << report.failure;
    throw std::runtime_error(m.str());
  }
  place_needle(d0);
}

// Updates each intact layer: pressed once the tip reaches its top, its peak
// force, and punctured when its criterion is met (the crack opened).
void AxisymmetricInsertionRun::detect_punctures() {
  const NeedleForce f = solver_.needle_force();
  for (std::size_t i = 0; i < n_layers_; ++i) {
    if (states_[i] == LayerState::Punctured) continue;
    const bool first_intact = static_cast<int>(i) == pressed_layer();
    if (states_[i] == LayerState::Untouched && first_intact && f.nodes_in_contact > 0 && tip_reached_top(i))
      states_[i] = LayerState::Pressed;
    if (states_[i] != LayerState::Pressed) continue;
    if (f.total_N > peak_force_[i]) {
      peak_force_[i] = f.total_N;
      peak_depth_[i] = depth_;
      peak_time_[i] = time_;
      peak_profile_[i] = layer_top_profile(i);
    }
    if (!layer_breaks(i, f.total_N, first_intact)) continue;
    open_crack(i);
    record_puncture(i, f.total_N);
  }
}

// Has the tip reached layer i's (displaced) top? (The skin: at first contact.)
bool AxisymmetricInsertionRun::tip_reached_top(std::size_t i) const {
  const auto u = solver_.displacement_at(mesh_.crack_radius_m, -scene_.layer_top_depth_m(i));
  return i == 0 || depth_ >= scene_.layer_top_depth_m(i) - u[1] - 1e-9;
}

// Layer i's puncture criterion: its cohesive crack open through its top
// (fracture energy), or the critical force / stretch (first intact layer only).
bool AxisymmetricInsertionRun::layer_breaks(std::size_t i, double force_N, bool first_intact) const {
  const PunctureCriterion& c = scene_.layers[i].puncture;
  if (c.kind == PunctureCriterion::Kind::FractureEnergy) return crack_through_top(i);
  if (!first_intact) return false;
  const bool by_force = c.kind == PunctureCriterion::Kind::CriticalForce;
  const double value =
      by_force ? force_N
               : solver_.max_principal_stretch(static_cast<int>(i), 2.0 * a_, -depth_ - 2.0 * a_, -depth_ + 2.0 * a_);
  return value >= (by_force ? c.critical_force_N : c.critical_stretch);
}

// Opens layer i's crack: a cohesive crack has opened itself; a crack tied
// until the force/stretch criterion is met is released now (cutting tips only).
void AxisymmetricInsertionRun::open_crack(std::size_t i) {
  if (scene_.layers[i].puncture.kind == PunctureCriterion::Kind::FractureEnergy) return;
  if (!cutting_)
    throw std::runtime_error("the puncture criterion of layer '" + scene_.layers[i].name +
                             "' is met, but a blunt (flat) punch cannot cut in the axisymmetric reference: "
                             "use needle tip bevel or hollow, or fem.geometry 3d");
  solver_.break_layer(static_cast<int>(i));
}

// Records layer i's puncture: the event (at its peak force), the surface
// before (at the peak) and now, a log line and a frame.
void AxisymmetricInsertionRun::record_puncture(std::size_t i, double force_after_N) {
  states_[i] = LayerState::Punctured;
  PunctureEvent e;
  e.layer = static_cast<int>(i);
  e.layer_name = scene_.layers[i].name;
  e.depth_m = peak_depth_[i];
  e.force_N = peak_force_[i];
  e.force_after_N = force_after_N;
  e.time_s = peak_time_[i];
  summary_.punctures.push_back(e);
  records_.add_recovery_profile(i, "before", peak_depth_[i], peak_profile_[i]);
  records_.add_recovery_profile(i, "after", depth_, layer_top_profile(i));
  std::ostringstream m;
  m << "fem: " << e.layer_name << " punctured: peak " << e.force_N << " N at " << e.depth_m * 1e3 << " mm, "
    << e.force_after_N << " N at " << depth_ * 1e3 << " mm";
  log(m.str());
  write_frame(time_);
}

// Puts the needle (a cutting needle or the flat punch) at tip depth `depth`.
void AxisymmetricInsertionRun::place_needle(double depth) {
  if (cutting_) {
    RigidNeedle n;
    n.edge_radius_m = mesh_.crack_radius_m;
    n.shaft_radius_m = a_;
    n.flank_angle_rad = scene_.needle.tip_angle_deg * kPi / 180.0;
    n.z_tip_m = -depth;
    solver_.set_cutting_needle(n);
  } else {
    solver_.set_flat_punch(a_, -depth);
  }
}

// The first layer not punctured (-1: all are).
int AxisymmetricInsertionRun::pressed_layer() const {
  for (std::size_t i = 0; i < n_layers_; ++i)
    if (states_[i] != LayerState::Punctured) return static_cast<int>(i);
  return -1;
}

// Layer i is punctured once its crack is fully open (damage >= kCutDamage)
// a little below its top: min(t/4, a), so that the crack has run into the
// layer, not only opened the edge of its surface.
bool AxisymmetricInsertionRun::crack_through_top(std::size_t i) const {
  const double top = scene_.layer_top_depth_m(i);
  const double margin = std::min(0.25 * scene_.layers[i].thickness_m, a_);
  return solver_.crack_front_depth_m(static_cast<int>(i), kCutDamage) >= top + margin - 1e-12;
}

}  // namespace axisymmetric_insertion

namespace {

// What rank 0 sends the other ranks: the error (empty if none) and the curve.
nlohmann::json outcome_to_json(const std::string& error, const FemRunSummary& summary) {
  nlohmann::json j;
  j["error"] = error;
  j["time_s"] = summary.time_s;
  j["depth_m"] = summary.depth_m;
  j["force_N"] = summary.force_N;
  j["peak_force_N"] = summary.peak_force_N;
  j["n_dofs"] = summary.n_dofs;
  j["wall_time_s"] = summary.wall_time_s;
  nlohmann::json ev = nlohmann::json::array();
  for (const auto& e : summary.punctures)
    ev.push_back({e.layer, e.layer_name, e.depth_m, e.force_N, e.force_after_N, e.time_s});
  j["punctures"] = ev;
  return j;
}

// The other ranks' copy of rank 0's outcome.
void outcome_from_json(const nlohmann::json& j, std::string& error, FemRunSummary& summary) {
  error = j["error"].get<std::string>();
  summary.geometry = "axisymmetric";
  summary.time_s = j["time_s"].get<std::vector<double>>();
  summary.depth_m = j["depth_m"].get<std::vector<double>>();
  summary.force_N = j["force_N"].get<std::vector<double>>();
  summary.peak_force_N = j["peak_force_N"].get<double>();
  summary.n_dofs = j["n_dofs"].get<std::size_t>();
  summary.wall_time_s = j["wall_time_s"].get<double>();
  for (const auto& e : j["punctures"]) {
    PunctureEvent p;
    p.layer = e[0].get<int>();
    p.layer_name = e[1].get<std::string>();
    p.depth_m = e[2].get<double>();
    p.force_N = e[3].get<double>();
    p.force_after_N = e[4].get<double>();
    p.time_s = e[5].get<double>();
    summary.punctures.push_back(p);
  }
}

// Rank 0 computed; the others learn the outcome (and the curve) from it.
void share_outcome(MPI_Comm comm, std::string& error, FemRunSummary& summary) {
  if (dealii::Utilities::MPI::n_mpi_processes(comm) == 1) return;
  const bool root = dealii::Utilities::MPI::this_mpi_process(comm) == 0;
  // The other ranks wait asleep (a blocking collective would spin a core
  // that rank 0's assembly threads use).
  MPI_Request ready;
  MPI_Ibarrier(comm, &ready);
  for (int done = 0; !done;) {
    MPI_Test(&ready, &done, MPI_STATUS_IGNORE);
    if (!done) std::this_thread::sleep_for(std::chrono::milliseconds(root ? 0 : 5));
  }
  const std::string text =
      dealii::Utilities::MPI::broadcast(comm, root ? outcome_to_json(error, summary).dump() : std::string(), 0);
  if (!root) outcome_from_json(nlohmann::json::parse(text), error, summary);
}

}  // namespace

FemRunSummary run_axisymmetric_insertion(const Scene& scene, const FemRunOptions& options, MPI_Comm comm) {
  FemRunSummary summary;
  std::string error;
  if (dealii::Utilities::MPI::this_mpi_process(comm) == 0) {
    try {
      widen_cpu_affinity();
      axisymmetric_insertion::AxisymmetricInsertionRun run(scene, options, comm, summary);  // mesh and solver
      try {
        run.walk_trajectory();  // per step: advance, detect punctures, record
      } catch (const std::exception& e) {
        run.write_outputs(e.what());  // the rows so far, "status": "failed" and why
        throw;
      }
      run.write_outputs();
    } catch (const std::exception& e) {
      error = e.what();
      if (error.empty()) error = "unknown error";
    }
  }
  share_outcome(comm, error, summary);
  if (!error.empty()) throw std::runtime_error(error);
  return summary;
}

void widen_cpu_affinity() {
#ifdef __linux__
  const long n = ::sysconf(_SC_NPROCESSORS_ONLN);
  cpu_set_t set;
  CPU_ZERO(&set);
  for (long c = 0; c < n && c < CPU_SETSIZE; ++c) CPU_SET(static_cast<int>(c), &set);
  (void)::sched_setaffinity(0, sizeof set, &set);
#endif
}

}  // namespace puncture::fem
