// host.hpp: the name of this machine, for provenance and staging file names.
//
// host_name(): gethostname() as it is ("unknown" if it fails); the machine of
//   a provenance (provenance.hpp).
// host_tag(): host_name() with every character other than letters, digits,
//   '-', '.' and '_' replaced by '_'; the "@<host>" of staging file names
//   (atomic_file.hpp writes it, interrupt_cleanup.hpp's stale-file check
//   compares it, so both must use this one function).
#pragma once

#include <string>

namespace puncture::io {

std::string host_name();
std::string host_tag();

}  // namespace puncture::io
