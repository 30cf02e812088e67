#include "puncture/shaft_pressure_relaxation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace puncture {

ShaftPressureRelaxation::ShaftPressureRelaxation(std::vector<PronyRelaxationTerm> terms) : terms_(std::move(terms)) {
  double min_tau_s = std::numeric_limits<double>::infinity();
  for (const PronyRelaxationTerm& t : terms_) {
    if (!(t.g > 0.0 && t.g <= 1.0) || !(t.tau_s > 0.0) || !std::isfinite(t.tau_s))
      throw std::invalid_argument("shaft pressure relaxation: every Prony term needs g in (0, 1] and a finite tau > 0");
    relaxed_fraction_ -= t.g;
    min_tau_s = std::min(min_tau_s, t.tau_s);
  }
  if (relaxed_fraction_ < -1e-12)
    throw std::invalid_argument("shaft pressure relaxation: the Prony terms' g sum to more than 1");
  relaxed_fraction_ = std::max(relaxed_fraction_, 0.0);
  merge_window_s_ = terms_.empty() ? 0.0 : kMergeFraction * min_tau_s;
  weighted_m_.assign(terms_.size(), 0.0);
  if (!terms_.empty()) stack_.reserve(kMaxEntries);
}

void ShaftPressureRelaxation::halve_stack() {
  // Merge the older half pairwise (their weights have decayed the longest);
  // the newer half keeps its resolution.
  const std::size_t older = stack_.size() / 2 - (stack_.size() / 2) % 2;
  std::size_t n = 0;
  for (std::size_t i = 0; i < older; i += 2) {
    const PassedLength& a = stack_[i];
    const PassedLength& b = stack_[i + 1];
    const double length_m = a.length_m + b.length_m;
    stack_[n++] = {length_m, length_m > 0.0 ? (a.time_s * a.length_m + b.time_s * b.length_m) / length_m : b.time_s};
  }
  for (std::size_t i = older; i < stack_.size(); ++i) stack_[n++] = stack_[i];
  stack_.resize(n);
}

double ShaftPressureRelaxation::update(double shaft_length_m, double time_s) {
  const double h = std::max(shaft_length_m, 0.0);
  if (terms_.empty()) return relaxed_m_ = h;
  const double dt = started_ ? std::max(time_s - time_s_, 0.0) : 0.0;
  if (!started_ || time_s > time_s_) time_s_ = time_s;
  started_ = true;
  if (dt > 0.0)
    for (std::size_t i = 0; i < terms_.size(); ++i) weighted_m_[i] *= std::exp(-dt / terms_[i].tau_s);
  if (h > length_m_) {
    // Newly passed shaft: weight 1 now.
    const double added = h - length_m_;
    if (!stack_.empty() && time_s_ - stack_.back().time_s <= merge_window_s_)
      stack_.back().length_m += added;
    else {
      if (stack_.size() == kMaxEntries) halve_stack();
      stack_.push_back({added, time_s_});
    }
    for (double& s : weighted_m_) s += added;
  } else if (h < length_m_) {
    // Withdrawn: the newest lengths leave first.
    double removed = length_m_ - h;
    while (removed > 0.0 && !stack_.empty()) {
      PassedLength& top = stack_.back();
      const double r = std::min(removed, top.length_m);
      for (std::size_t i = 0; i < terms_.size(); ++i)
        weighted_m_[i] -= r * std::exp(-(time_s_ - top.time_s) / terms_[i].tau_s);
      top.length_m -= r;
      removed -= r;
      if (!(top.length_m > 0.0)) stack_.pop_back();
    }
  }
  length_m_ = h;
  if (h == 0.0) {
    stack_.clear();
    std::fill(weighted_m_.begin(), weighted_m_.end(), 0.0);
  }
  double relaxed = relaxed_fraction_ * h;
  for (std::size_t i = 0; i < terms_.size(); ++i) {
    weighted_m_[i] = std::clamp(weighted_m_[i], 0.0, h);  // round-off of the pops
    relaxed += terms_[i].g * weighted_m_[i];
  }
  return relaxed_m_ = relaxed;
}

}  // namespace puncture
