// The haptic tick does no heap allocation. Global operator new/delete are
// replaced by counting versions, and malloc/calloc/realloc are interposed
// (Eigen allocates with malloc, not new); both counters must stay at zero
// over many ticks of the Table 2 scene with every effect on, for each
// integrator.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "puncture/simulator.hpp"
#include "table2_scene.hpp"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);
}

namespace {
std::atomic<bool> counting{false};
std::atomic<long> new_calls{0};
std::atomic<long> malloc_calls{0};
}  // namespace

extern "C" {
void* malloc(std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) ++malloc_calls;
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t m) {
  if (counting.load(std::memory_order_relaxed)) ++malloc_calls;
  return __libc_calloc(n, m);
}
void* realloc(void* p, std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) ++malloc_calls;
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
}

void* operator new(std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) ++new_calls;
  if (void* p = __libc_malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { __libc_free(p); }
void operator delete[](void* p) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::size_t) noexcept { __libc_free(p); }

using namespace puncture;

TEST(NoAllocation, CountersSeeAnAllocation) {
  // The instrument works: a vector and an Eigen vector are both counted.
  counting = true;
  auto* v = new std::vector<int>(10);
  Eigen::VectorXd e(100);
  counting = false;
  delete v;
  EXPECT_GE(new_calls.load(), 2);     // the vector object and its buffer
  EXPECT_GE(malloc_calls.load(), 1);  // Eigen's buffer
  new_calls = 0;
  malloc_calls = 0;
}

class NoAllocationTick : public ::testing::TestWithParam<const char*> {};

TEST_P(NoAllocationTick, FullInsertionAllocatesNothing) {
  Scene scene = test::table2_scene(GetParam());
  ASSERT_TRUE(scene.effects.surface_force && scene.effects.damping && scene.effects.resumption);
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  const ScriptedTrajectory tr(scene.insertion);
  const int ticks = static_cast<int>(tr.duration() / 1e-3);
  // Sample the trajectory outside the counted region (NeedleState is plain data).
  std::vector<NeedleState> states;
  states.reserve(ticks);
  for (int i = 0; i < ticks; ++i) states.push_back(tr.sample(i * 1e-3));

  new_calls = 0;
  malloc_calls = 0;
  double sum = 0.0;
  counting = true;
  for (const NeedleState& s : states) sum += sim.tick(s).total_force_N;
  counting = false;
  EXPECT_EQ(new_calls.load(), 0) << GetParam();
  EXPECT_EQ(malloc_calls.load(), 0) << GetParam();
  EXPECT_TRUE(std::isfinite(sum));
  EXPECT_EQ(sim.puncture_events().size(), 3u);  // the counted ticks did the whole job
}

INSTANTIATE_TEST_SUITE_P(Integrators, NoAllocationTick, ::testing::Values("quasi_static", "explicit", "implicit"));

// Every force-law effect on (layer interaction, cutting, Karnopp friction,
// tip stiffening, critical-force and critical-energy breakthrough) and the
// needle off the scene axis, so that the force meshes are laid out again at
// the contact point inside the counted ticks.
TEST_P(NoAllocationTick, EveryForceLawEffectOffAxisAllocatesNothing) {
  Scene scene = test::table2_scene(GetParam());
  scene.effects.layer_interaction = scene.effects.cutting = scene.effects.friction = scene.effects.stiffening = true;
  for (std::size_t k = 0; k < scene.layers.size(); ++k) {
    ForceLaw& law = scene.layers[k].force_law;
    law.breakthrough.kind = k == 1 ? BreakthroughCriterion::Kind::CriticalEnergy : BreakthroughCriterion::Kind::CriticalForce;
    law.breakthrough.critical_force_N = 0.6;
    law.breakthrough.critical_energy_J = 0.2e-3;
    law.cutting_force_N = 0.3;
    law.friction.dynamic_N_per_m = law.friction.static_N_per_m = 10.0;
    law.stiffening.quadratic_N_per_m2 = 2e4;
  }
  scene.layers[0].force_mesh.virtual_stiffness_N_per_m = 2000.0;
  PunctureSimulator sim(scene, test::plane_surfaces(scene));
  const ScriptedTrajectory tr(scene.insertion);
  const int ticks = static_cast<int>(tr.duration() / 1e-3);
  std::vector<NeedleState> states;
  states.reserve(ticks);
  for (int i = 0; i < ticks; ++i) {
    states.push_back(tr.sample(i * 1e-3));
    states.back().tip_position_m.x() += 2e-3;
    states.back().tip_position_m.y() -= 1e-3;
  }

  new_calls = 0;
  malloc_calls = 0;
  double sum = 0.0, cutting = 0.0, friction = 0.0;
  counting = true;
  for (const NeedleState& s : states) {
    const TickResult& r = sim.tick(s);
    sum += r.total_force_N;
    cutting += r.cutting_force_N;
    friction += std::abs(r.friction_force_N);
  }
  counting = false;
  EXPECT_EQ(new_calls.load(), 0) << GetParam();
  EXPECT_EQ(malloc_calls.load(), 0) << GetParam();
  EXPECT_TRUE(std::isfinite(sum));
  EXPECT_EQ(sim.puncture_events().size(), 3u);
  EXPECT_GT(cutting, 0.0);
  EXPECT_GT(friction, 0.0);
  EXPECT_NEAR(sim.force_mesh(0)->rest_positions()(0, 0), 2e-3, 1e-15);  // laid where the needle touched
  EXPECT_NEAR(sim.force_mesh(2)->rest_positions()(1, 0), -1e-3, 1e-15);
}
