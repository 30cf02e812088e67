// volumetric_model.cpp: needle insertion into a tetrahedral mesh with an
// internal force law, integrated by SUNDIALS; see volumetric_model.hpp.
#include "puncture/comparison/volumetric_model.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace puncture::comparison {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kGeometryTolerance_m = 1e-6;

}  // namespace

VolumetricSettings volumetric_settings(const Scene& scene) {
  VolumetricSettings s;
  s.integrator = parse_integrator_kind(scene.comparison.integrator);
  s.relative_tolerance = scene.comparison.relative_tolerance;
  s.absolute_tolerance_m = scene.comparison.absolute_tolerance_m;
  s.mass_damping_per_s = scene.comparison.mass_damping_per_s;
  s.stiffness_damping_s = scene.comparison.stiffness_damping_s;
  return s;
}

// ---------------------------------------------------------------------------- model

VolumetricNeedleModel::VolumetricNeedleModel(const Scene& scene, std::shared_ptr<const TetMesh> mesh,
                                             std::unique_ptr<InternalForceLaw> law, const VolumetricSettings& settings,
                                             std::string description)
    : scene_(&scene), mesh_(std::move(mesh)), law_(std::move(law)), settings_(settings),
      description_(std::move(description)) {
  if (!mesh_ || !law_) throw std::invalid_argument("VolumetricNeedleModel: null mesh or law");
  const int n_layers = static_cast<int>(scene.layers.size());
  meshing::check_tet_mesh(*mesh_, n_layers);
  nodes_ = mesh_->node_count();
  extra_ = law_->extra_state_size();
  needle_radius_m_ = scene.needle.radius_m;
  rest_ = Eigen::Map<const Eigen::VectorXd>(mesh_->points_m.data(), 3 * nodes_);
  removed_.assign(mesh_->tets.size(), 0);

  // Fixed base and side, as the FEM reference.
  const double radius = 0.5 * scene.sample.diameter_m;
  const double base_z = -scene.total_thickness_m();
  dof_.assign(static_cast<std::size_t>(nodes_), Dof::Free);
  for (int a = 0; a < nodes_; ++a) {
    const Eigen::Vector3d p = mesh_->points_m.col(a);
    if (p.z() < base_z + kGeometryTolerance_m || std::hypot(p.x(), p.y()) > radius - kGeometryTolerance_m)
      dof_[static_cast<std::size_t>(a)] = Dof::Fixed;
  }

  // Per layer: contact candidates and the ring-criterion probe.
  std::vector<std::vector<char>> in_layer(static_cast<std::size_t>(n_layers),
                                          std::vector<char>(static_cast<std::size_t>(nodes_), 0));
  for (std::size_t t = 0; t < mesh_->tets.size(); ++t)
    for (int i = 0; i < 4; ++i) in_layer[static_cast<std::size_t>(mesh_->layer[t])][mesh_->tets[t][i]] = 1;
  for (int k = 0; k < n_layers; ++k) {
    const double top = -scene.layer_top_depth_m(static_cast<std::size_t>(k));
    const LayerBreakthroughRule breakthrough = LayerBreakthroughRule::of(scene, static_cast<std::size_t>(k));
    LayerSurfaceProbe probe(*mesh_, k, top, breakthrough.rings().points_m());
    for (std::size_t i = 0; i < probe.size(); ++i)
      if (!probe.found(i))
        throw std::invalid_argument("VolumetricNeedleModel: ring point " + std::to_string(i) + " of layer \"" +
                                    scene.layers[static_cast<std::size_t>(k)].name +
                                    "\" is not on the layer's top face of the mesh");
    layers_.push_back(LayerRuntime{top, {}, LayerState::Untouched, false, breakthrough, probe, {}});
    for (int a = 0; a < nodes_; ++a) {
      const Eigen::Vector3d p = mesh_->points_m.col(a);
      if (in_layer[static_cast<std::size_t>(k)][static_cast<std::size_t>(a)] &&
          std::abs(p.z() - top) < kGeometryTolerance_m &&
          std::hypot(p.x(), p.y()) <= needle_radius_m_ + kGeometryTolerance_m)
        layers_.back().candidates.push_back(a);
    }
    if (layers_.back().candidates.empty())
      throw std::invalid_argument("VolumetricNeedleModel: no mesh node of layer \"" +
                                  scene.layers[static_cast<std::size_t>(k)].name +
                                  "\" lies on its top face inside the needle radius (refine the mesh at the axis)");
  }

  compute_masses();
  y_ = Eigen::VectorXd::Zero(6 * nodes_ + extra_);
  y_.head(3 * nodes_) = rest_;
  law_->extra_state_decay_rates(decay_rates_);
  const std::vector<std::pair<int, int>> pairs = tet_node_pairs(*mesh_);
  if (settings_.integrator == IntegratorKind::ImplicitBdf) tangent_ = NodeBlockMatrix(nodes_, pairs);
  if (settings_.stiffness_damping_s > 0.0 || law_->is_linear()) {
    rest_tangent_ = NodeBlockMatrix(nodes_, pairs);
    compute_rest_tangent();
  }
  work_f_ = Eigen::VectorXd::Zero(3 * nodes_);
}

VolumetricNeedleModel::~VolumetricNeedleModel() = default;

bool VolumetricNeedleModel::update_contacts(double z_tip, double velocity_z, bool withdrawing) {
  bool changed = false;
  checked_force_N_ = std::numeric_limits<double>::quiet_NaN();
  double snap = 0.0;
  if (withdrawing && active_ < layers_.size()) {
    // A contact node in tension lets go (a linear law's force from K0's
    // columns, not a sweep over every element at every haptic step).
    const bool linear = law_->is_linear();
    if (!linear) compute_forces(y_, work_f_);
    for (int a = 0; a < nodes_; ++a) {
      if (dof_[static_cast<std::size_t>(a)] != Dof::Contact) continue;
      if ((linear ? linear_force_z_N(a) : work_f_[3 * a + 2]) < 0.0) {
        dof_[static_cast<std::size_t>(a)] = Dof::Free;
        changed = true;
      }
    }
  }
  // No node joins the contact set while the needle is withdrawn: a released
  // surface that recovers behind the retreating tip would otherwise be put
  // back onto it, be released again in tension on the next step, and so on
  // (a contact chatter that restarted the integrator at every haptic step).
  // A layer whose surface the relaxation below presses onto the tip beyond
  // its critical force breaks on this step, and the contacts are updated
  // again for the layer under it (a chain of breaks).
  for (bool again = true; again;) {
    again = false;
    while (active_ < layers_.size() && !withdrawing) {
      LayerRuntime& layer = layers_[active_];
      bool started_now = false;
      for (int a : layer.candidates) {
        if (dof_[static_cast<std::size_t>(a)] != Dof::Free) continue;
        if (y_[3 * a + 2] < z_tip) continue;  // the tip has not reached this node
        if (!layer.contact_started) {
          started_now = true;
          layer.baseline_m = layer.ring_probe.deflection_m(y_, mesh_->points_m);
          layer.contact_started = true;
          layer.state = LayerState::Pressed;
          layer.breakthrough.start(-z_tip, time_);
        }
        snap = std::max(snap, y_[3 * a + 2] - z_tip);
        y_[3 * a + 2] = z_tip;
        y_.segment<3>(3 * nodes_ + 3 * a) = Eigen::Vector3d(0.0, 0.0, velocity_z);
        dof_[static_cast<std::size_t>(a)] = Dof::Contact;
        changed = true;
      }
      // Layers break only while the needle advances (the loop's condition),
      // and not on the step their contact starts: a surface put onto the tip
      // from above is brought to equilibrium below first (its force before
      // that is the snap's) and checked there (break_after_relaxation).
      if (!layer.contact_started || started_now) break;
      std::vector<double> deflection;
      if (layer.breakthrough.needs_deflection()) {
        deflection = layer.ring_probe.deflection_m(y_, mesh_->points_m);
        for (std::size_t i = 0; i < deflection.size(); ++i) deflection[i] -= layer.baseline_m[i];
      }
      const double force = layer.breakthrough.needs_force() ? contact_force_N() : 0.0;
      layer.breakthrough.advance(-z_tip, force, time_);
      if (!layer.breakthrough.broken(force, deflection)) {
        if (layer.breakthrough.needs_force()) checked_force_N_ = force;  // the step's contact force, if nothing moves now
        break;
      }
      puncture_active_layer(layer.breakthrough.needs_force() ? layer.breakthrough.load_at_break_N(force) : contact_force_N());
      changed = true;
    }
    // A node put onto the tip from far above it (the next layer's surface after
    // a puncture lies below the tip) is an impulsive deformation; like the FEM
    // reference, find the equilibrium with the new contact set at once.
    if (changed) static_factor_valid_ = false;
    if (snap > snap_relax_threshold_m_ && !settings_.quasi_static) {
      const bool relaxed = relax_to_equilibrium();
      checked_force_N_ = std::numeric_limits<double>::quiet_NaN();
      snap = 0.0;
      again = relaxed && break_after_relaxation(z_tip);  // (changed is already set: a node joined the contact)
    }
  }
  return changed;
}

bool VolumetricNeedleModel::break_after_relaxation(double z_tip) {
  if (active_ >= layers_.size()) return false;
  LayerRuntime& layer = layers_[active_];
  if (!layer.contact_started || !layer.breakthrough.needs_force()) return false;
  const double force = contact_force_N();
  layer.breakthrough.advance(-z_tip, force, time_);  // the tip has not moved: no work is booked
  if (!layer.breakthrough.broken(force)) {
    checked_force_N_ = force;
    return false;
  }
  puncture_active_layer(layer.breakthrough.load_at_break_N(force));
  return true;
}

bool VolumetricNeedleModel::factorise_static_tangent(const Eigen::VectorXd& state) {
  NodeBlockMatrix K(nodes_, tet_node_pairs(*mesh_));
  law_->add_tangent(state.head(3 * nodes_), 0.0, K);
  Eigen::SparseMatrix<double> A = K.matrix();
  for (Eigen::Index j = 0; j < A.outerSize(); ++j) {
    const bool col_free = dof_[static_cast<std::size_t>(j / 3)] == Dof::Free;
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, j); it; ++it) {
      if (col_free && dof_[static_cast<std::size_t>(it.row() / 3)] == Dof::Free) continue;
      it.valueRef() = it.row() == it.col() ? 1.0 : 0.0;
    }
  }
  ++relaxation_factorisations_;
  if (!settings_.quasi_static) {
    static_factor_valid_ = relax_factor_.factorize(A);
    return static_factor_valid_;
  }
  if (!static_pattern_analysed_) {
    static_solver_.analyzePattern(A);
    static_pattern_analysed_ = true;
  }
  static_solver_.factorize(A);
  static_factor_valid_ = static_solver_.info() == Eigen::Success;
  return static_factor_valid_;
}

bool VolumetricNeedleModel::relax_to_equilibrium() {
  const int n3 = 3 * nodes_;
  Eigen::VectorXd state = y_;
  state.segment(n3, n3).setZero();  // quasi-static: no damping forces
  auto residual = [&](const Eigen::VectorXd& y, Eigen::VectorXd& r) {
    compute_forces(y, r);
    for (int d = 0; d < n3; ++d)
      if (dof_[static_cast<std::size_t>(d / 3)] != Dof::Free) r[d] = 0.0;
    return r.norm();
  };
  Eigen::VectorXd r(n3), trial_r(n3);
  double norm = residual(state, r);
  double reaction = 0.0;  // force scale: the load the contact nodes carry
  {
    Eigen::VectorXd f(n3);
    compute_forces(state, f);
    for (int d = 0; d < n3; ++d)
      if (dof_[static_cast<std::size_t>(d / 3)] == Dof::Contact) reaction += std::abs(f[d]);
  }
  // Out-of-balance forces below 1e-5 of the load the needle carries. A
  // mass-spring network under a needle can have neighbouring equilibria
  // (compressed springs buckle), where Newton stalls with tiny line-search
  // steps: it stops after three slow iterations on fresh tangents and keeps
  // the best state.
  const double target = 1e-5 * std::max(reaction, 1e-12) + 1e-14;
  bool fresh = false;  // the factorisation was made at this state
  int slow = 0;
  for (int iteration = 0; iteration < 40 && norm > target && slow < 3; ++iteration) {
    if (!static_factor_valid_) {
      if (!factorise_static_tangent(state)) return false;  // leave the state to the dynamics
      fresh = true;
    }
    const Eigen::VectorXd step =  // K dx = f (f = -dW/dx)
        settings_.quasi_static ? Eigen::VectorXd(static_solver_.solve(r)) : relax_factor_.solve(r);
    double scale = 1.0, trial_norm = std::numeric_limits<double>::infinity();
    Eigen::VectorXd trial = state;
    if (step.allFinite()) {
      for (int cut = 0; cut < 8; ++cut, scale *= 0.5) {
        trial.head(n3) = state.head(n3) + scale * step;
        trial_norm = residual(trial, trial_r);
        if (std::isfinite(trial_norm) && trial_norm < norm) break;
      }
    }
    if (!(trial_norm < norm)) {
      if (fresh) break;  // no descent even with a new tangent
      static_factor_valid_ = false;
      continue;
    }
    // Modified Newton: keep the factorisation while it still contracts
    // (factorisations cost far more than iterations).
    if (trial_norm > 0.7 * norm) {
      if (fresh && trial_norm > 0.9 * norm) ++slow;
      static_factor_valid_ = false;
    }
    fresh = false;
    state = trial;
    r = trial_r;
    norm = trial_norm;
  }
  for (int a = 0; a < nodes_; ++a)
    if (dof_[static_cast<std::size_t>(a)] == Dof::Contact)
      state.segment<3>(n3 + 3 * a) = y_.segment<3>(n3 + 3 * a);  // contact nodes keep the needle's velocity
  y_ = state;
  ++relaxations_;
  return true;
}

void VolumetricNeedleModel::puncture_active_layer(double load_at_break_N) {
  const int k = static_cast<int>(active_);
  layers_[active_].break_force_N = load_at_break_N;
  for (std::size_t t = 0; t < mesh_->tets.size(); ++t)
    if (mesh_->layer[t] == k && mesh_->needle_column[t]) removed_[t] = 1;
  law_->set_removed(removed_);
  compute_rest_tangent();
  for (Dof& d : dof_)
    if (d == Dof::Contact) d = Dof::Free;
  compute_masses();
  for (int a = 0; a < nodes_; ++a)
    if (dof_[static_cast<std::size_t>(a)] == Dof::Fixed) y_.segment<3>(3 * nodes_ + 3 * a).setZero();
  layers_[active_].state = LayerState::Punctured;
  ++active_;
  have_tangent_ = false;
  drop_factors();
  static_factor_valid_ = false;
  ++events_;
}

double VolumetricNeedleModel::linear_force_z_N(int a) const {
  // f = -K0 (x - X) - beta K0 v (the law's forces and the stiffness damping).
  const Eigen::SparseMatrix<double>& K0 = rest_tangent_.matrix();
  const double beta = settings_.stiffness_damping_s;
  const int n3 = 3 * nodes_;
  double force = 0.0;
  for (Eigen::SparseMatrix<double>::InnerIterator it(K0, 3 * a + 2); it; ++it) {
    const Eigen::Index i = it.row();
    force -= it.value() * (y_[i] - rest_[i] + beta * y_[n3 + i]);
  }
  return force;
}

double VolumetricNeedleModel::contact_force_N() {
  // Without contact nodes the force is zero: no internal force evaluation
  // (a sweep over every element) on the steps before and between contacts.
  if (std::none_of(dof_.begin(), dof_.end(), [](Dof d) { return d == Dof::Contact; })) return 0.0;
  double force = 0.0;
  if (law_->is_linear()) {  // a few hundred products instead of a sweep over every element at every haptic step
    for (int a = 0; a < nodes_; ++a)
      if (dof_[static_cast<std::size_t>(a)] == Dof::Contact) force += linear_force_z_N(a);
  } else {
    compute_forces(y_, work_f_);
    for (int a = 0; a < nodes_; ++a)
      if (dof_[static_cast<std::size_t>(a)] == Dof::Contact) force += work_f_[3 * a + 2];
  }
  if (!std::isfinite(force)) throw std::runtime_error(name() + ": the contact force became non-finite at t = " +
                                                      std::to_string(time_) + " s");
  return force;
}

void VolumetricNeedleModel::step_quasi_static(double t, double z_tip, bool withdrawing) {
  started_ = true;
  time_ = t;
  for (int a = 0; a < nodes_; ++a)
    if (dof_[static_cast<std::size_t>(a)] == Dof::Contact) y_[3 * a + 2] = z_tip;
  y_.segment(3 * nodes_, 3 * nodes_).setZero();
  update_contacts(z_tip, 0.0, withdrawing);
  relax_to_equilibrium();
  y_.segment(3 * nodes_, 3 * nodes_).setZero();
}

void VolumetricNeedleModel::start_integration(double t, double z_tip, double velocity_z) {
  started_ = true;
  time_ = t;
  needle_velocity_z_ = velocity_z;
  IntegratorSettings integration;
  integration.kind = settings_.integrator;
  integration.relative_tolerance = settings_.relative_tolerance;
  integration.max_bdf_order = 2;  // A-stable: the mesh's oscillations stay damped
  integration.absolute_tolerance.resize(y_.size());
  integration.absolute_tolerance.head(3 * nodes_).setConstant(settings_.absolute_tolerance_m);
  integration.absolute_tolerance.segment(3 * nodes_, 3 * nodes_).setConstant(1e3 * settings_.absolute_tolerance_m);
  if (extra_ > 0) integration.absolute_tolerance.tail(extra_).setConstant(law_->extra_state_abs_tolerance());
  update_contacts(z_tip, velocity_z, false);
  integrator_ = std::make_unique<SundialsIntegrator>(static_cast<OdeSystem&>(*this), integration, time_, y_);
}

void VolumetricNeedleModel::advance_dynamics(double t, double z_tip, double velocity_z) {
  // The contact nodes follow the needle with its mean velocity over this step.
  double z_contact = 0.0;
  bool any_contact = false;
  for (int a = 0; a < nodes_; ++a)
    if (dof_[static_cast<std::size_t>(a)] == Dof::Contact) {
      z_contact = y_[3 * a + 2];
      any_contact = true;
      break;
    }
  double step_velocity = any_contact ? (z_tip - z_contact) / (t - time_) : velocity_z;
  // Rounding of the positions must not count as a change of speed.
  if (std::abs(step_velocity - needle_velocity_z_) <= 1e-9 * std::max(std::abs(step_velocity), 1e-6))
    step_velocity = needle_velocity_z_;
  if (any_contact && step_velocity != needle_velocity_z_) {
    for (int a = 0; a < nodes_; ++a)
      if (dof_[static_cast<std::size_t>(a)] == Dof::Contact) y_[3 * nodes_ + 3 * a + 2] = step_velocity;
    integrator_->reinit(time_, y_);
  }
  needle_velocity_z_ = step_velocity;
  try {
    integrator_->advance(t, y_);
  } catch (const std::runtime_error&) {
    // Recovery: the BDF history can lead the error test to fail over and
    // over (h collapsing to ~1e-7 s) on a smooth stretch of the insertion;
    // restart from the last accepted haptic state (order 1, new history,
    // fresh tangent and factorisation) and try once more. A second failure
    // stops the run with the integrator's message.
    ++failure_restarts_;
    have_tangent_ = false;
    drop_factors();
    integrator_->reinit(time_, y_);
    integrator_->advance(t, y_);
  }
  time_ = t;
  for (int a = 0; a < nodes_; ++a)
    if (dof_[static_cast<std::size_t>(a)] == Dof::Contact) y_[3 * a + 2] = z_tip;
}

double VolumetricNeedleModel::step(const NeedleState& needle) {
  const double t = needle.time_s;
  const double z_tip = needle.tip_position_m.z();
  const double velocity_z = -needle.axial_velocity_m_per_s * needle.direction.dot(-Eigen::Vector3d::UnitZ());
  const bool withdrawing = needle.axial_velocity_m_per_s < 0.0;
  if (!needle.tip_position_m.allFinite() || !std::isfinite(t))
    throw std::invalid_argument(name() + ": non-finite needle state");
  if (settings_.quasi_static) {
    // Equilibrium at every step (the identification's fast mode): contact
    // nodes move with the needle, no inertia, no damping.
    step_quasi_static(t, z_tip, withdrawing);
    return contact_force_N();
  }
  if (!started_) {
    start_integration(t, z_tip, velocity_z);
    return contact_force_N();
  }
  const bool touched = std::any_of(layers_.begin(), layers_.end(), [](const LayerRuntime& l) { return l.contact_started; });
  if (t > time_ && !touched) {
    // Before the needle first touches the tissue the mesh rests unloaded
    // (y' = 0 exactly: no contact, no body forces): nothing to integrate. The
    // integrator restarts from this state at the first contact.
    time_ = t;
  } else if (t > time_) {
    advance_dynamics(t, z_tip, velocity_z);
  }
  const long punctures_before = events_;
  if (update_contacts(z_tip, velocity_z, withdrawing)) {
    // The prescribed dofs changed: the factorisation is kept as a lagged
    // preconditioner (see preconditioner_setup); a puncture drops it, and
    // the restart after it starts from the integrator's own step estimate
    // (the freed nodes' fast transient).
    if (!settings_.lag_preconditioner) drop_factors();
    needle_velocity_z_ = velocity_z;
    integrator_->reinit(time_, y_,
                        events_ != punctures_before ? SundialsIntegrator::FirstStep::Estimate
                                                    : SundialsIntegrator::FirstStep::FromLastStep);
  }
  // The breakthrough check may have evaluated it already on this state.
  return std::isfinite(checked_force_N_) ? checked_force_N_ : contact_force_N();
}

int VolumetricNeedleModel::contact_node_count() const {
  return static_cast<int>(std::count(dof_.begin(), dof_.end(), Dof::Contact));
}

double VolumetricNeedleModel::mechanical_energy_J() const {
  const Eigen::VectorXd v = y_.segment(3 * nodes_, 3 * nodes_);
  return law_->energy_J(y_.head(3 * nodes_)) + 0.5 * v.dot(mass_.cwiseProduct(v));
}

std::vector<double> VolumetricNeedleModel::surface_deflection_m(std::size_t layer, const std::vector<double>& r_m) const {
  constexpr int kAzimuths = 8;
  std::vector<Eigen::Vector2d> points;
  for (double r : r_m)
    for (int j = 0; j < kAzimuths; ++j) {
      const double phi = 2.0 * kPi * (j + 0.5) / kAzimuths;
      points.emplace_back(r * std::cos(phi), r * std::sin(phi));
    }
  const LayerSurfaceProbe probe(*mesh_, static_cast<int>(layer), layers_.at(layer).top_z_m, points);
  const std::vector<double> d = probe.deflection_m(y_, mesh_->points_m);
  std::vector<double> out(r_m.size(), 0.0);
  for (std::size_t i = 0; i < r_m.size(); ++i) {
    int found = 0;
    for (int j = 0; j < kAzimuths; ++j)
      if (probe.found(i * kAzimuths + static_cast<std::size_t>(j))) {
        out[i] += d[i * kAzimuths + static_cast<std::size_t>(j)];
        ++found;
      }
    out[i] = found ? out[i] / found : std::numeric_limits<double>::quiet_NaN();
  }
  return out;
}

ModelSize VolumetricNeedleModel::model_size() const {
  ModelSize s;
  s.dofs = static_cast<long>(y_.size());
  s.nodes = nodes_;
  s.elements = mesh_->tet_count();
  std::size_t bytes = law_->memory_bytes();
  bytes += static_cast<std::size_t>(mesh_->points_m.size()) * sizeof(double) +
           mesh_->tets.size() * (sizeof(Eigen::Vector4i) + sizeof(int) + 1);
  bytes += static_cast<std::size_t>(y_.size() + rest_.size() + mass_.size() + work_f_.size()) * sizeof(double);
  bytes += 2 * static_cast<std::size_t>(y_.size()) * sizeof(double);  // integrator state copies
  if (settings_.integrator == IntegratorKind::ImplicitBdf) {
    const std::size_t nnz = static_cast<std::size_t>(tangent_.matrix().nonZeros());
    bytes += 2 * nnz * (sizeof(double) + sizeof(int));  // tangent and eliminated system
    bytes += (factors_.factor_nonzeros() + relax_factor_.factor_nonzeros()) * (sizeof(double) + sizeof(int));
    // SUNDIALS BDF history (up to 6 vectors) and GMRES basis (krylov + 2 vectors).
    bytes += 18 * static_cast<std::size_t>(y_.size()) * sizeof(double);
  } else {
    bytes += 8 * static_cast<std::size_t>(y_.size()) * sizeof(double);  // ERK stages
  }
  s.memory_bytes = bytes;
  return s;
}

Eigen::Matrix3Xd VolumetricNeedleModel::deformed_points() const {
  return Eigen::Map<const Eigen::Matrix3Xd>(y_.data(), 3, nodes_);
}

VolumeFrame VolumetricNeedleModel::volume_frame() const {
  VolumeFrame frame;
  const Eigen::Matrix3Xd x = deformed_points();
  frame.points_m = x.transpose();
  frame.displacement_m = (x - mesh_->points_m).transpose();
  const long kept = static_cast<long>(std::count(removed_.begin(), removed_.end(), 0));
  frame.tets.resize(kept, 4);
  frame.layer.resize(kept);
  long row = 0;
  for (std::size_t t = 0; t < mesh_->tets.size(); ++t) {
    if (removed_[t]) continue;
    frame.tets.row(row) = mesh_->tets[t].transpose();
    frame.layer[row] = mesh_->layer[t];
    ++row;
  }
  return frame;
}

ElementInversion VolumetricNeedleModel::element_inversion() const {
  return measure_element_inversion(*mesh_, y_.head(3 * nodes_), removed_);
}

std::string VolumetricNeedleModel::integrator_report() const {
  if (settings_.quasi_static) {
    std::ostringstream out;
    out << "quasi-static: equilibrium at every step by modified Newton, " << relaxation_factorisations_
        << " sparse LDL^T factorisations";
    return out.str();
  }
  if (!integrator_) return "not started";
  const IntegratorStats s = integrator_->stats();
  std::ostringstream out;
  out << to_string(integrator_->kind()) << ": " << s.steps << " steps, " << s.rhs_evaluations
      << " rhs evaluations, " << s.linear_iterations << " GMRES iterations, " << s.preconditioner_setups
      << " preconditioner set-ups, " << s.error_test_failures << " error-test and " << s.convergence_failures
      << " convergence failures; " << factorisations_ << " sparse Cholesky factorisations (" << factorisation_seconds_
      << " s; " << factors_.fallbacks() << " by the LDL^T fallback), " << mass_only_setups_ << " diagonal preconditioners; " << relaxations_
      << " static relaxations after a contact jump (" << relaxation_factorisations_ << " sparse Cholesky factorisations); "
      << s.reinitialisations << " restarts (contact, puncture, speed changes), " << failure_restarts_
      << " of them after an integration failure";
  return out.str();
}

long VolumetricNeedleModel::recovered_steps() const {
  if (!integrator_) return 0;
  const IntegratorStats s = integrator_->stats();
  return s.error_test_failures + s.convergence_failures + failure_restarts_;
}

}  // namespace puncture::comparison
