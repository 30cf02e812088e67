// python_progress.hpp: a long C++ call that released the GIL calls back into
// Python now and then: to let Ctrl-C through (PyErr_CheckSignals, which acts
// on the main thread only) and to call the user's progress callback.
//
// When Python raises (KeyboardInterrupt, or the callback's own exception),
// the error is kept and CallbackAborted (a C++ exception) is thrown to unwind
// the C++ call; every later call throws it again at once, so a call that
// swallows one exception (a failed model run inside an optimiser) stops at
// the next. After the C++ call, rethrow_if_raised() re-raises the Python
// error as it was. Outputs of the commands are staged, so an aborted call
// leaves nothing half-written.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <stdexcept>

#include <pybind11/pybind11.h>

namespace puncture::python {

class CallbackAborted : public std::runtime_error {
 public:
  CallbackAborted() : std::runtime_error("interrupted from Python (Ctrl-C or the progress callback raised)") {}
};

class PythonCallback {
 public:
  /// `callback` may be None (then only signals are checked). Needs the GIL.
  explicit PythonCallback(pybind11::object callback) : callback_(std::move(callback)) {}

  /// From any thread that does not hold the GIL: checks Ctrl-C, then calls
  /// the callback (when not None) with `args`.
  template <class... Args>
  void operator()(Args&&... args) {
    invoke([&](const pybind11::object& callback) {
      if (!callback.is_none()) callback(std::forward<Args>(args)...);
    });
  }

  /// From any thread that does not hold the GIL: checks Ctrl-C only (for the
  /// steps of a long call the callback does not report, e.g. an FEM reference
  /// computed inside a calibration).
  void check_signals() {
    invoke([](const pybind11::object&) {});
  }

  bool raised() const { return raised_; }

  /// With the GIL: re-raises the kept Python error, if any.
  void rethrow_if_raised() {
    if (raised_) throw pybind11::error_already_set(*error_);
  }

 private:
  template <class Call>
  void invoke(Call&& call) {
    if (raised_) throw CallbackAborted();
    std::lock_guard<std::mutex> lock(mutex_);  // one call into Python at a time
    if (raised_) throw CallbackAborted();
    pybind11::gil_scoped_acquire gil;
    try {
      if (PyErr_CheckSignals() != 0) throw pybind11::error_already_set();
      call(callback_);
    } catch (pybind11::error_already_set& e) {
      error_ = std::make_shared<pybind11::error_already_set>(std::move(e));
      raised_ = true;
      throw CallbackAborted();
    }
  }

  pybind11::object callback_;
  std::mutex mutex_;
  std::atomic<bool> raised_{false};
  std::shared_ptr<pybind11::error_already_set> error_;
};

}  // namespace puncture::python
