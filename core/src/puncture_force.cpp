#include "puncture/puncture_force.hpp"

#include <algorithm>

namespace puncture {

const char* to_string(LayerState state) {
  switch (state) {
    case LayerState::Untouched: return "untouched";
    case LayerState::Pressed: return "pressed";
    case LayerState::Punctured: return "punctured";
  }
  return "unknown";
}

double shaft_length_in_layer_m(double tip_depth_m, double layer_top_depth_m, double layer_thickness_m) {
  return std::clamp(tip_depth_m - layer_top_depth_m, 0.0, layer_thickness_m);
}

}  // namespace puncture
