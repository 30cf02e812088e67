// pvd.hpp: ParaView collection file (.pvd): a time series of datasets, so a
// directory of frames opens in ParaView as one animated object. The one .pvd
// writer of the project: the real-time run, the validation and comparison
// reports and the FEM reference (both geometries) write through it.
//
// In:  entries (time_s in s, part index >= 0, file name relative to the .pvd),
//      optionally a provenance and a PvdFormat.
// Out: the staged file <relative_name> in the session, or the text:
//   <?xml version="1.0"?>
//   <!--<format.comment>-->                                           (when given)
//   <!-- provenance: command: ... | program_version: ... | ... -->   (when given)
//   <VTKFile type="Collection" version="0.1" byte_order="LittleEndian">
//     <Collection> <DataSet timestep=".." group="" part=".." file=".."/> ...
// With the default PvdFormat times are printed in the shortest round-trip
// form and file names are XML-escaped. Throws std::invalid_argument for a
// non-finite time, a negative part or an empty file name.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "puncture/io/provenance.hpp"

namespace puncture::io {

class OutputSession;

struct PvdEntry {
  double time_s = 0.0;  ///< simulation time of the dataset, s
  int part = 0;         ///< part index (several datasets at one time, e.g. one per layer)
  std::string file;     ///< dataset file, relative to the .pvd
};

/// How a .pvd is spelt. The defaults are the project's collections (run,
/// validation, comparison); the FEM reference keeps the spelling its files
/// always had (fem_pvd_format() in reference_fem).
struct PvdFormat {
  /// Name of the attribute of <VTKFile> that says "LittleEndian"
  /// ("byte_order"; deal.II spells it "ByteOrder"); empty: no attribute.
  std::string byte_order_attribute = "byte_order";
  bool group_attribute = true;  ///< group="" in every <DataSet>
  /// Significant digits of the timestep ("%.<n>g"); 0: shortest round trip.
  int time_digits = 0;
  /// Text of an XML comment right after the declaration ("<!--" text "-->\n");
  /// empty: none.
  std::string comment;
};

/// The .pvd document as text; with a provenance, an XML comment carries it.
std::string pvd_document(const std::vector<PvdEntry>& entries, const Provenance* provenance = nullptr,
                         const PvdFormat& format = {});

void write_pvd(OutputSession& session, const std::string& relative_name, const std::vector<PvdEntry>& entries,
               const Provenance* provenance = nullptr);

/// The document written to `path` with write_file_atomically (atomic_file.hpp),
/// for writers without an OutputSession (the FEM reference on its MPI ranks).
void write_pvd_file(const std::filesystem::path& path, const std::vector<PvdEntry>& entries,
                    const Provenance* provenance = nullptr, const PvdFormat& format = {});

}  // namespace puncture::io
