// model_factory.hpp: every comparison model by name, built from the scene.
//
//   realtime                  the SHF + MSM real-time model (model/realtime_model.hpp)
//   shf                       SH-only surfaces (surface_models.hpp)
//   msm                       volumetric mass-spring (internal_forces.hpp)
//   mass_tensor               Cotin's linear tensor-mass
//   nonlinear_mass_tensor     Picinbono's StVK tensor-mass
//   viscoelastic_mass_tensor  StVK tensor-mass with a Prony series
//   bem                       boundary elements on the layered half-space
// ("fem", the deal.II reference, is not built here: its curve comes from the
// cached FEM run.) The volumetric models need the tetrahedral mesh
// (meshing/tet); the others take nullptr.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "puncture/comparison/comparison_model.hpp"
#include "puncture/meshing/tet_mesh.hpp"

namespace puncture::comparison {

using meshing::TetMesh;  // the comparison models work on meshing's tetrahedral slab

/// The names above, in table order.
const std::vector<std::string>& comparison_model_names();
bool is_volumetric_model(const std::string& name);

/// Throws std::invalid_argument for an unknown name or a volumetric model without a mesh.
std::unique_ptr<ComparisonModel> make_comparison_model(const std::string& name, const Scene& scene,
                                                       std::shared_ptr<const TetMesh> mesh);

/// The real-time model behind the comparison interface: its surface force,
/// layer states and force-mesh ring deflections.
std::unique_ptr<ComparisonModel> make_realtime_comparison_model(const Scene& scene);

}  // namespace puncture::comparison
