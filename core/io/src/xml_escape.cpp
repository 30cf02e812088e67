#include "puncture/io/xml_escape.hpp"

namespace puncture::io {

std::string xml_escape(const std::string& text, bool escape_apostrophe) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'':
        if (escape_apostrophe) out += "&apos;";
        else out += c;
        break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace puncture::io
