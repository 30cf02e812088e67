#include "puncture/realtime/model_supplier.hpp"

#include <chrono>

namespace puncture::realtime {

ModelSupplier::ModelSupplier(Builder build) : build_(std::move(build)) {
  initial_ = build_().release();
  in_use_ = initial_;
  built_ = 1;
  thread_ = std::thread([this] { builder_loop(); });
}

ModelSupplier::~ModelSupplier() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  delete spare_.exchange(nullptr);
  delete retired_.exchange(nullptr);
  if (!finished_) delete in_use_.exchange(nullptr);
}

void ModelSupplier::collect(RealtimeModel* model) {
  if (!model) return;
  events_.push_back(model->simulator ? model->simulator->puncture_events() : std::vector<PunctureEvent>{});
  for (PunctureEvent& e : events_.back()) e.layer_name = {};  // a view into the model destroyed below
  delete model;
}

void ModelSupplier::builder_loop() {
  bool failed = false;
  while (!stop_.load(std::memory_order_acquire)) {
    if (RealtimeModel* old = retired_.exchange(nullptr, std::memory_order_acq_rel)) collect(old);
    if (!failed && !spare_.load(std::memory_order_acquire)) {
      try {
        std::unique_ptr<RealtimeModel> m = build_();
        built_.fetch_add(1);
        spare_.store(m.release(), std::memory_order_release);
      } catch (const std::exception& e) {
        failed = true;
        std::lock_guard<std::mutex> lock(error_mutex_);
        error_ = e.what();
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

RealtimeModel* ModelSupplier::try_exchange(RealtimeModel* old) noexcept {
  if (retired_.load(std::memory_order_acquire) != nullptr) return nullptr;  // the last one is not collected yet
  RealtimeModel* fresh = spare_.exchange(nullptr, std::memory_order_acq_rel);
  if (!fresh) return nullptr;
  retired_.store(old, std::memory_order_release);
  in_use_.store(fresh, std::memory_order_release);
  return fresh;
}

std::vector<std::vector<PunctureEvent>> ModelSupplier::finish() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (!finished_) {
    if (RealtimeModel* old = retired_.exchange(nullptr)) collect(old);
    collect(in_use_.exchange(nullptr));
    finished_ = true;
  }
  return std::move(events_);
}

std::string ModelSupplier::error() const {
  std::lock_guard<std::mutex> lock(error_mutex_);
  return error_;
}

ModelSupplier::Builder scene_model_builder(const Scene& scene) {
  return [&scene] { return std::make_unique<RealtimeModel>(build_realtime_model(scene)); };
}

}  // namespace puncture::realtime
