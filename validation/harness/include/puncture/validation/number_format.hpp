// number_format.hpp: how reports and tables print a number.
//
// In:  a value and a count of significant digits.
// Out: the text std::ostream writes with std::setprecision(digits) (default
//      floating notation, so 0.0001234 or 1.234e+06 as the stream chooses;
//      non-finite values as the stream writes them). Callers that print
//      non-finite values differently ("n/a", "–") test for them first.
#pragma once

#include <iomanip>
#include <sstream>
#include <string>

namespace puncture::validation {

inline std::string significant_digits(double value, int digits) {
  std::ostringstream s;
  s << std::setprecision(digits) << value;
  return s.str();
}

}  // namespace puncture::validation
