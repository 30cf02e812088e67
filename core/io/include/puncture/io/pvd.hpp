// pvd.hpp: ParaView collection file (.pvd): a time series of datasets, so a
// directory of frames opens in ParaView as one animated object.
//
// In:  entries (time_s in s, part index >= 0, file name relative to the .pvd).
// Out: the staged file <relative_name> in the session:
//   <?xml version="1.0"?>
//   <!-- provenance: command: ... | program_version: ... | ... -->   (when given)
//   <VTKFile type="Collection" version="0.1" byte_order="LittleEndian">
//     <Collection> <DataSet timestep=".." group="" part=".." file=".."/> ...
// Times are printed in the shortest round-trip form; file names are XML-escaped.
// Throws std::invalid_argument for a non-finite time, a negative part or an
// empty file name.
#pragma once

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

/// The .pvd document as text; with a provenance, an XML comment carries it.
std::string pvd_document(const std::vector<PvdEntry>& entries, const Provenance* provenance = nullptr);

void write_pvd(OutputSession& session, const std::string& relative_name, const std::vector<PvdEntry>& entries,
               const Provenance* provenance = nullptr);

}  // namespace puncture::io
