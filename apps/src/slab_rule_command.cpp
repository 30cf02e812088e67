// `puncture slab-rule`: fits the slab rule (validation/harness/include/
// puncture/validation/slab_rule.hpp) on presets calibrated on a family of
// slabs and writes slab_rule.json (what `puncture validate --cases FILE
// --slab-rule slab_rule.json` applies to the cases on other slabs) and
// slab_rule.md.
#include <iostream>

#include <nlohmann/json.hpp>

#include "command_errors.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/io/atomic_file.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/io/provenance_json.hpp"
#include "puncture/scene_io.hpp"
#include "puncture/validation/slab_rule.hpp"

namespace puncture::apps {

int slab_rule_command(const SlabRuleOptions& options, std::ostream& stdout_stream, std::ostream& err) {
  NullStream quiet;
  std::ostream& out = options.quiet ? quiet : stdout_stream;
  return report_errors(err, "", [&]() -> int {
    if (options.presets.size() < 2) throw UsageError("slab-rule needs presets calibrated on two slabs or more");
    std::vector<nlohmann::json> presets;
    std::vector<std::string> names;
    std::vector<validation::PresetCalibration> calibrations;
    validation::SlabRule rule;
    try {
      for (const std::filesystem::path& p : options.presets) {
        load_scene(p);  // each preset must be a valid scene (SceneError names the file and field)
        presets.push_back(nlohmann::json::parse(io::read_text_file(p)));
        names.push_back(p.string());
        // What its calibration identified: <stem>.provenance.json beside it (puncture calibrate).
        std::filesystem::path record = p;
        record.replace_extension(".provenance.json");
        validation::PresetCalibration c;
        if (std::filesystem::exists(record)) {
          nlohmann::json provenance;
          try {
            provenance = nlohmann::json::parse(io::read_text_file(record));
          } catch (const nlohmann::json::parse_error& e) {
            throw InputError(record.string() + ": not valid JSON: " + e.what());
          }
          c = validation::read_preset_calibration(provenance, record.string());
        }
        if (!c.known)
          err << "warning: " << p.string() << ": no calibration record (" << record.string()
              << " with calibrated_values): every value is taken as identified\n";
        calibrations.push_back(c);
      }
      rule = validation::fit_slab_rule(presets, names, calibrations);
    } catch (const std::invalid_argument& e) {
      throw InputError(e.what());
    }
    const std::filesystem::path dir = options.output_dir.empty() ? std::filesystem::path("out/slab_rule") : options.output_dir;
    std::string command = "puncture slab-rule";
    for (const std::string& n : names) command += " " + n;
    command += " -o " + dir.string();
    const io::Provenance provenance = io::make_provenance(command);
    io::OutputSession session(dir);
    session.write_text("slab_rule.json", validation::slab_rule_json(rule, io::provenance_json(provenance)).dump(2) + "\n");
    session.write_text("slab_rule.md", validation::slab_rule_markdown(rule, command,
                                                                      "git " + provenance.git_revision + ", " +
                                                                          provenance.machine + ", " + provenance.date_utc));
    session.commit();
    std::size_t count = 0, not_ruled = 0;
    for (const auto& l : rule.layers) count += l.parameters.size(), not_ruled += l.not_ruled.size();
    out << "Slab rule: " << count << " parameter(s) in " << rule.layers.size() << " layer(s) from " << presets.size()
        << " presets (" << not_ruled << " not ruled: identified on too few slabs)\nOutputs in " << dir.string() << "/ (slab_rule.json, slab_rule.md)\n";
    return 0;
  });
}

}  // namespace puncture::apps
