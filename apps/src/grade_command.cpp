// `puncture grade`: comprehensive weighted grading of models from a CSV of
// scores (seed paper Sec. 3.3: Delphi subjective weights, mean-square-error
// objective weights, combined with preference coefficient mu).
#include <iomanip>
#include <iostream>

#include "puncture/apps/commands.hpp"
#include "puncture/io/output_session.hpp"
#include "puncture/validation/grading.hpp"

namespace puncture::apps {

int grade_command(const GradeOptions& options, std::ostream& out, std::ostream& err) {
  try {
    if (!(options.mu > 0.0 && options.mu < 1.0)) throw std::invalid_argument("--mu must be in (0, 1)");
    const validation::GradingResult result = validation::grade_scores_csv(options.scores, {}, options.mu);
    const std::filesystem::path dir = options.output_dir.empty() ? std::filesystem::path("out/grading") : options.output_dir;
    io::OutputSession session(dir);
    validation::write_grading_csv(session, "grading", result);
    session.commit();
    out << "Comprehensive scores (mu = " << result.mu << "):\n";
    for (const auto& m : result.models)
      out << "  " << std::left << std::setw(12) << m.model << std::right << std::fixed << std::setprecision(3)
          << m.mean_score << '\n';
    out.unsetf(std::ios::floatfield);
    out << "Outputs in " << dir.string() << "/ (grading_*.csv)\n";
    return 0;
  } catch (const std::exception& e) {
    err << "error: " << e.what() << '\n';
    return 1;
  }
}

}  // namespace puncture::apps
