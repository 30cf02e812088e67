#include "puncture/io/host.hpp"

#include <unistd.h>

#include <cctype>

namespace puncture::io {

std::string host_name() {
  char host[256] = "unknown";
  gethostname(host, sizeof host - 1);
  host[sizeof host - 1] = '\0';
  return host;
}

std::string host_tag() {
  std::string h = host_name();
  for (char& c : h)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '.' || c == '_')) c = '_';
  return h;
}

}  // namespace puncture::io
