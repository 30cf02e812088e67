// `puncture grade`: comprehensive weighted grading of models from a CSV of
// scores (seed paper Sec. 3.3: Delphi subjective weights, mean-square-error
// objective weights, combined with preference coefficient mu).
#include <iomanip>
#include <iostream>

#include "command_errors.hpp"
#include "puncture/apps/commands.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/io/provenance.hpp"
#include "puncture/validation/grading.hpp"

namespace puncture::apps {

int grade_command(const GradeOptions& options, std::ostream& stdout_stream, std::ostream& err) {
  NullStream quiet;
  std::ostream& out = options.quiet ? quiet : stdout_stream;
  return report_errors(err, options.scores.string(), [&]() -> int {
    if (!(options.mu > 0.0 && options.mu < 1.0)) throw UsageError("--mu must be in (0, 1)");
    validation::GradingResult result;
    try {
      result = validation::grade_scores_csv(options.scores, {}, options.mu);
    } catch (const std::runtime_error& e) {
      throw InputError(e.what());  // a bad scores file is bad input (exit code 2)
    } catch (const std::invalid_argument& e) {
      throw InputError(e.what());
    }
    const std::filesystem::path dir = options.output_dir.empty() ? std::filesystem::path("out/grading") : options.output_dir;
    const io::Provenance provenance = io::make_provenance("puncture grade " + options.scores.string() + " -o " +
                                                         dir.string() + " --mu " + std::to_string(options.mu));
    io::OutputSession session(dir);
    validation::write_grading_csv(session, "grading", result, &provenance);
    session.commit();
    out << "Comprehensive scores (mu = " << result.mu << "):\n";
    for (const auto& m : result.models)
      out << "  " << std::left << std::setw(12) << m.model << std::right << std::fixed << std::setprecision(3)
          << m.mean_score << '\n';
    out.unsetf(std::ios::floatfield);
    out << "Outputs in " << dir.string() << "/ (grading_*.csv)\n";
    return 0;
  });
}

}  // namespace puncture::apps
