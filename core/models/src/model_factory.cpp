// model_factory.cpp: comparison models by name, and the real-time model
// behind the comparison interface; see model_factory.hpp.
#include "puncture/comparison/model_factory.hpp"

#include <algorithm>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "puncture/comparison/surface_models.hpp"
#include "puncture/comparison/volumetric_model.hpp"
#include "puncture/model/realtime_model.hpp"

namespace puncture::comparison {

std::vector<LayerElasticity> layer_elasticity(const Scene& scene) {
  std::vector<LayerElasticity> out;
  const std::vector<double>& scale = scene.comparison.stiffness_scale;
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    const Layer& l = scene.layers[k];
    const double s = k < scale.size() ? scale[k] : 1.0;
    out.push_back({s * l.material.youngs_modulus_Pa, l.material.poisson_ratio, l.density_kg_per_m3});
  }
  return out;
}

namespace {

class RealtimeComparisonModel final : public ComparisonModel {
 public:
  explicit RealtimeComparisonModel(const Scene& scene) : scene_(&scene), model_(build_realtime_model(scene)) {}
  std::string name() const override { return "realtime"; }
  std::string description() const override {
    std::ostringstream s;
    s << "SHF + MSM real-time model: SH surfaces of degree " << scene_->realtime.sh_degree
      << ", hexagonal force mesh per layer, " << scene_->realtime.integrator << " force-mesh integrator";
    return s.str();
  }
  /// The tick with the scene's whole force law; the contact force is the
  /// needle layer's surface force (TickResult::surface_force_N; its tip force
  /// also holds the open crack's bevel part, which the harness counts with the
  /// cutting). Cutting, shaft friction and damping are added by the harness
  /// with the same formulas for every model (run_comparison_model,
  /// model_comparison.hpp).
  double step(const NeedleState& needle) override { return model_.simulator->tick(needle).surface_force_N; }
  LayerState layer_state(std::size_t k) const override { return model_.simulator->layer_state(k); }
  double break_force_N(std::size_t k) const override {
    for (const PunctureEvent& e : model_.simulator->puncture_events())
      if (e.layer == static_cast<int>(k)) return e.surface_force_N;
    return std::numeric_limits<double>::quiet_NaN();
  }
  bool layer_touched(std::size_t k) const override { return model_.simulator->has_contact(k); }
  std::vector<double> surface_deflection_m(std::size_t k, const std::vector<double>& r_m) const override {
    std::vector<double> out(r_m.size(), 0.0);
    const ForceMesh* mesh = model_.simulator->force_mesh(k);
    if (!mesh || model_.simulator->layer_state(k) != LayerState::Pressed) return out;
    // With layer interaction the layers below carry the layer down as well.
    const std::size_t n = model_.simulator->layer_count();
    const double base = k + 1 < n ? model_.simulator->surface_deflection_m(k + 1) : 0.0;
    const double L = mesh->params().spacing_L_m;
    const int w = mesh->rings();
    for (std::size_t i = 0; i < r_m.size(); ++i) {
      const double s = r_m[i] / L;  // ring j sits at r = (j - 1) L
      const int j = static_cast<int>(s);
      if (j + 1 >= w) {
        out[i] = j + 1 == w && s == j ? mesh->ring_mean_deflection_m(w) : 0.0;
        continue;
      }
      const double f = s - j;
      out[i] = (1.0 - f) * mesh->ring_mean_deflection_m(j + 1) + f * mesh->ring_mean_deflection_m(j + 2);
    }
    if (base != 0.0)
      for (double& d : out) d += base;
    return out;
  }
  ModelSize model_size() const override {
    ModelSize s;
    std::size_t bytes = 0;
    for (std::size_t k = 0; k < scene_->layers.size(); ++k) {
      const long l = model_.surfaces[k]->degree();
      bytes += static_cast<std::size_t>(3 * (l + 1) * (l + 1)) * sizeof(double);  // Eq. 3 coefficients
      if (const ForceMesh* mesh = model_.simulator->force_mesh(k)) {
        const long n = mesh->node_count();
        s.nodes += n;
        s.dofs += n;
        s.elements += 3 * static_cast<long>(mesh->rings()) * (mesh->rings() - 1);
        // positions, rest, normals (3 x N each); z, v, influence, rhs, work; the
        // lattice's neighbour lists; the implicit LDL^T factor (about 7 N entries).
        bytes += static_cast<std::size_t>(n) * (9 * sizeof(double) + 5 * sizeof(double) + 8 * sizeof(int) +
                                                7 * (sizeof(double) + sizeof(int)));
        if (model_.simulator->resumption(k)) bytes += static_cast<std::size_t>(n) * 10 * sizeof(double);
      }
    }
    s.memory_bytes = bytes;
    return s;
  }

 private:
  const Scene* scene_;
  RealtimeModel model_;
};

}  // namespace

const std::vector<std::string>& comparison_model_names() {
  static const std::vector<std::string> names{"realtime",     "shf", "msm", "mass_tensor", "nonlinear_mass_tensor",
                                              "viscoelastic_mass_tensor", "bem"};
  return names;
}

bool is_volumetric_model(const std::string& name) {
  return name == "msm" || name == "mass_tensor" || name == "nonlinear_mass_tensor" || name == "viscoelastic_mass_tensor";
}

std::unique_ptr<ComparisonModel> make_realtime_comparison_model(const Scene& scene) {
  return std::make_unique<RealtimeComparisonModel>(scene);
}

std::unique_ptr<ComparisonModel> make_comparison_model(const std::string& name, const Scene& scene,
                                                       std::shared_ptr<const TetMesh> mesh) {
  if (name == "realtime") return make_realtime_comparison_model(scene);
  if (name == "shf") return std::make_unique<SphericalHarmonicModel>(scene);
  if (name == "bem") return std::make_unique<BoundaryElementModel>(scene);
  if (!is_volumetric_model(name)) {
    std::string known;
    for (const std::string& n : comparison_model_names()) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown comparison model '" + name + "' (known: " + known + ", fem)");
  }
  if (!mesh) throw std::invalid_argument("model '" + name + "' needs the tetrahedral mesh of the slab");
  const VolumetricSettings settings = volumetric_settings(scene);
  const std::vector<LayerElasticity> elasticity = layer_elasticity(scene);
  const std::string integration = std::string(", ") + to_string(settings.integrator);
  std::ostringstream mesh_text;
  mesh_text << " on " << mesh->node_count() << " nodes / " << mesh->tet_count() << " tetrahedra";
  if (name == "msm") {
    const SpringKind springs = parse_spring_kind(scene.comparison.mass_spring_springs);
    return std::make_unique<VolumetricNeedleModel>(
        scene, mesh,
        std::make_unique<MassSpringLaw>(*mesh, elasticity, scene.comparison.mass_spring_stiffness_scale, springs),
        settings,
        std::string("volumetric mass-spring (one ") + to_string(springs) +
            " spring per edge, Van Gelder stiffness)" + mesh_text.str() + integration);
  }
  if (name == "mass_tensor")
    return std::make_unique<VolumetricNeedleModel>(scene, mesh, std::make_unique<LinearTensorMass>(*mesh, elasticity),
                                                   settings,
                                                   "Cotin linear tensor-mass" + mesh_text.str() + integration);
  if (name == "nonlinear_mass_tensor")
    return std::make_unique<VolumetricNeedleModel>(scene, mesh, std::make_unique<StvkTensorMass>(*mesh, elasticity),
                                                   settings,
                                                   "Picinbono St Venant-Kirchhoff tensor-mass" + mesh_text.str() + integration);
  PronySeries prony{scene.comparison.prony_g, scene.comparison.prony_tau_s};
  std::ostringstream terms;
  for (std::size_t k = 0; k < prony.g.size(); ++k)
    terms << (k ? ", " : "") << "g = " << prony.g[k] << " tau = " << prony.tau_s[k] << " s";
  return std::make_unique<VolumetricNeedleModel>(
      scene, mesh, std::make_unique<ViscoelasticTensorMass>(*mesh, elasticity, prony), settings,
      "visco-elastic StVK tensor-mass (Prony " + terms.str() + ")" + mesh_text.str() + integration);
}

}  // namespace puncture::comparison
