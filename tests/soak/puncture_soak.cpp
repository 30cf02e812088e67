// puncture_soak: the long soak for results/soak/ (scripts/results_soak.sh).
//   puncture_soak [--ticks N] [--seed S] [--out DIR]
// Prints progress, writes DIR/soak.md (table with provenance) and
// DIR/soak.json; exit code 0 if every check passed, 1 otherwise.
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "puncture/io/output_session.hpp"
#include "puncture/io/provenance_json.hpp"
#include "soak_driver.hpp"

int main(int argc, char** argv) {
  using namespace puncture;
  soak::SoakOptions options;
  options.ticks = 10000000;
  std::string out_dir = "results/soak";
  std::string command = "puncture_soak";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    command += " " + a;
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "puncture_soak: " << a << " needs a value\n";
        std::exit(2);
      }
      command += " " + std::string(argv[i + 1]);
      return argv[++i];
    };
    if (a == "--ticks") options.ticks = std::stoll(value());
    else if (a == "--seed") options.seed = std::stoull(value());
    else if (a == "--out") out_dir = value();
    else {
      std::cerr << "usage: puncture_soak [--ticks N] [--seed S] [--out DIR]\n";
      return 2;
    }
  }
  const soak::SoakReport r = soak::run_soak(options, [](double f) {
    std::cout << "[soak] " << std::lround(100 * f) << " %\n" << std::flush;
  });
  const io::Provenance provenance = io::make_provenance(command);

  std::string effects;
  for (const auto& e : r.effects) effects += (effects.empty() ? "" : ", ") + e;
  std::ostringstream md;
  md << "# Soak of the haptic tick\n\n"
     << "Made by `" << command << "` (scripts/results_soak.sh) on " << provenance.machine << ", "
     << provenance.date_utc << ", program " << provenance.program_version << ", git " << provenance.git_revision
     << ".\n\n"
     << "Random needle trajectories (tests/soak/soak_driver.hpp): scenes/default.json with every effect on ("
     << effects << "), a fresh model per episode with the integrator cycling through quasi_static, explicit and "
     << "implicit; segments to random depths from the start height to 2 mm above the sample base at random speeds "
     << "(log-uniform " << options.min_speed_mm_per_s << "-" << options.max_speed_mm_per_s << " mm/s), random dwells "
     << "(probability " << options.dwell_probability << " after a segment, up to " << options.max_dwell_s
     << " s), reversals, a random lateral offset of the needle's entry point up to " << options.max_lateral_offset_mm
     << " mm and a random inclination of the needle up to " << options.max_angle_deg
     << " deg to the surface normal at any azimuth (the tip on the inclined line). Seed " << options.seed << ".\n\n"
     << "| quantity | value |\n|---|---|\n"
     << "| haptic ticks | " << r.ticks << " |\n"
     << "| episodes (models built) | " << r.episodes << " |\n"
     << "| ticks quasi_static / explicit / implicit | " << r.ticks_per_integrator[0] << " / "
     << r.ticks_per_integrator[1] << " / " << r.ticks_per_integrator[2] << " |\n"
     << "| layer breakthroughs | " << r.punctures << " |\n"
     << "| episodes that punctured every layer | " << r.episodes_all_punctured << " |\n"
     << "| direction reversals | " << r.reversals << " |\n"
     << "| dwell ticks | " << r.dwell_ticks << " |\n"
     << "| fastest needle | " << std::setprecision(4) << r.max_speed_mm_per_s << " mm/s |\n"
     << "| largest inclination | " << r.max_angle_deg << " deg |\n"
     << "| largest needle force | " << r.max_abs_force_N << " N |\n"
     << "| largest force-mesh energy | " << r.max_energy_J << " J |\n"
     << "| largest energy / work done on the meshes | " << r.max_energy_to_work << " (bound: 1 + "
     << options.energy_rel_tolerance << ") |\n"
     << "| ticks with a non-finite force or energy | " << r.non_finite << " |\n"
     << "| energy-bound violations | " << r.energy_violations << " |\n"
     << "| heap allocations inside tick() | " << r.allocations
     << (r.allocation_count_from_sanitizer ? " (AddressSanitizer hook)" : " (counting operator new and malloc)")
     << " |\n"
     << "| tick wall time, median / p99 (every 50th tick) | " << r.median_tick_us << " / " << r.p99_tick_us
     << " us |\n"
     << "| wall time | " << r.wall_time_s << " s |\n"
     << "| result | " << (r.passed() ? "PASSED" : "FAILED") << " |\n";
  for (const auto& f : r.failures) md << "\n- " << f;
  md << "\n";

  nlohmann::json j;
  j["provenance"] = io::provenance_json(provenance);
  j["ticks"] = r.ticks;
  j["episodes"] = r.episodes;
  j["effects"] = r.effects;
  j["ticks_per_integrator"] = {{"quasi_static", r.ticks_per_integrator[0]},
                               {"explicit", r.ticks_per_integrator[1]},
                               {"implicit", r.ticks_per_integrator[2]}};
  j["punctures"] = r.punctures;
  j["episodes_all_punctured"] = r.episodes_all_punctured;
  j["reversals"] = r.reversals;
  j["dwell_ticks"] = r.dwell_ticks;
  j["max_abs_force_N"] = r.max_abs_force_N;
  j["max_energy_J"] = r.max_energy_J;
  j["max_energy_to_work"] = r.max_energy_to_work;
  j["non_finite"] = r.non_finite;
  j["energy_violations"] = r.energy_violations;
  j["allocations_in_tick"] = r.allocations;
  j["median_tick_us"] = r.median_tick_us;
  j["p99_tick_us"] = r.p99_tick_us;
  j["wall_time_s"] = r.wall_time_s;
  j["passed"] = r.passed();
  j["failures"] = r.failures;

  io::OutputSession session(out_dir);
  session.write_text("soak.md", md.str());
  session.write_text("soak.json", j.dump(2) + "\n");
  session.commit();
  std::cout << md.str();
  return r.passed() ? 0 : 1;
}
