// provenance.hpp: who/what/where/when for every output file, so a reader can
// reproduce it.
//
// make_provenance(command) -> Provenance: the command line that made the file,
// the program version and the git revision of the source tree the binary was
// built from (generated at build time by core/io/cmake/write_build_info.cmake;
// "<hash>-dirty" when tracked files differed from that commit, "unknown"
// outside a git checkout), the UTC date (ISO 8601, "2026-11-21T23:59:00Z")
// and the machine ("host (CPU model, N cores, BLAS)": the BLAS when one is
// loaded, blas_library()).
//
// How each kind of file carries it:
//   CSV    "# key: value" comment lines before the header (csv_table.hpp,
//          csv_writer.hpp; the readers of csv_reader.hpp keep them as metadata)
//   JSON   a "provenance" object (provenance_json.hpp)
//   .pvd   an XML comment after the XML declaration (pvd.hpp)
//   .vtp   string arrays in the dataset's field data (validation/io)
//   .vtu   text written by another library: add_provenance_field_data (vtk_xml_field_data.hpp)
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace puncture::io {

/// Version of the program (CMake project version).
const char* program_version();
/// Git revision the binary was built from ("abc1234", "abc1234-dirty" or "unknown").
const char* git_revision();

std::string utc_timestamp();    ///< now, e.g. "2026-11-21T23:59:00Z"
/// The BLAS this process has loaded (the folder Debian's alternatives keep
/// it in, e.g. "openblas-serial"; "reference BLAS" for Debian's libblas), or
/// "" when none is loaded: CHOLMOD's and UMFPACK's factorisations, and so the
/// FEM's and the tensor-mass models' last digits and speed, depend on it.
std::string blas_library();
std::string machine_summary();  ///< e.g. "host (Intel Xeon ..., 2 cores, openblas-serial)"

struct Provenance {
  std::string command;
  std::string program_version;
  std::string git_revision;
  std::string date_utc;
  std::string machine;
};

/// Provenance of a file made now by `command_line`.
Provenance make_provenance(const std::string& command_line);

/// The fields in a fixed order: command, program_version, git_revision,
/// date_utc, machine. Line breaks inside values are replaced by spaces.
std::vector<std::pair<std::string, std::string>> provenance_fields(const Provenance& p);

/// "# command: ...\n# program_version: ...\n..." (one "# key: value" line per field).
std::string provenance_comment_lines(const Provenance& p);

}  // namespace puncture::io
