// model_supplier.hpp: fresh tissue models for the haptic thread, built and
// destroyed off the haptic thread.
//
// A fresh (untouched) tissue means a new RealtimeModel: building one fits the
// SH surfaces and factorises the force meshes, which allocates and takes tens
// of milliseconds. The supplier's builder thread keeps one spare model ready;
// the haptic thread swaps it in with try_exchange() (two atomic exchanges, no
// lock, no allocation) and hands the old model back for the builder thread to
// destroy, after it has copied the old model's puncture events.
//   In:  a builder function (called on the builder thread, and once in the
//        constructor for the initial model).
//   Out: initial(); try_exchange() (haptic thread); finish() -> all puncture
//        events, per model, in order.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "puncture/model/realtime_model.hpp"

namespace puncture::realtime {

class ModelSupplier {
 public:
  using Builder = std::function<std::unique_ptr<RealtimeModel>()>;

  /// Builds the initial model now (exceptions propagate) and starts the builder thread.
  explicit ModelSupplier(Builder build);
  ~ModelSupplier();
  ModelSupplier(const ModelSupplier&) = delete;
  ModelSupplier& operator=(const ModelSupplier&) = delete;

  /// The first model. The supplier owns every model; the one in use is
  /// destroyed by finish() or by the destructor (stop the haptic loop first).
  RealtimeModel* initial() const { return initial_; }

  /// Haptic thread: a fresh model in exchange for `old` (which the builder
  /// thread destroys later), or nullptr (and `old` stays in use) when no spare
  /// is ready yet. Never blocks or allocates.
  RealtimeModel* try_exchange(RealtimeModel* old) noexcept;

  /// Stops the builder thread and destroys every model. Returns the puncture
  /// events of every model used, in order (layer_name is cleared: it viewed
  /// the destroyed model; use the layer index). Call once, after the haptic loop stopped.
  std::vector<std::vector<PunctureEvent>> finish();

  /// Empty unless building a spare failed (the message of the exception).
  std::string error() const;
  int models_built() const { return built_.load(); }

 private:
  void builder_loop();
  void collect(RealtimeModel* model);

  Builder build_;
  RealtimeModel* initial_ = nullptr;
  std::atomic<RealtimeModel*> in_use_{nullptr};
  bool finished_ = false;
  std::atomic<RealtimeModel*> spare_{nullptr};
  std::atomic<RealtimeModel*> retired_{nullptr};
  std::atomic<bool> stop_{false};
  std::atomic<int> built_{0};
  std::vector<std::vector<PunctureEvent>> events_;  ///< builder thread until finish()
  mutable std::mutex error_mutex_;                  ///< never taken by the haptic thread
  std::string error_;
  std::thread thread_;
};

/// The builder of a session's models: build_realtime_model(scene), the effects
/// the scene lists (the same model as `puncture run`). `scene` must outlive
/// the supplier.
ModelSupplier::Builder scene_model_builder(const Scene& scene);

}  // namespace puncture::realtime
