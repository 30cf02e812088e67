// solver_timing.hpp (internal): reading a deal.II TimerOutput's running totals.
//
// section_wall_seconds(timer, section): wall seconds spent so far in `section`
//   of `timer` (its total over every enter/leave; 0 before its first use). The
//   solvers time their phases with TimerOutput::Scope and report a phase's
//   time in one Newton iteration as the difference of two such totals.
#pragma once

#include <deal.II/base/timer.h>

#include <string>

namespace puncture::fem {

inline double section_wall_seconds(const dealii::TimerOutput& timer, const std::string& section) {
  const auto totals = timer.get_summary_data(dealii::TimerOutput::total_wall_time);
  const auto it = totals.find(section);
  return it == totals.end() ? 0.0 : it->second;
}

}  // namespace puncture::fem
