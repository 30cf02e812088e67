// vtk_xml_field_data.hpp: provenance (and other text) as field data of a VTK
// XML file whose text another library produced (deal.II's DataOut writes
// .vtu/.pvtu text without a way to add field data). No VTK needed.
//
// In:  the text of a VTK XML file (.vtu, .pvtu, .vtp, ...: <VTKFile> holding
//      one dataset element such as <UnstructuredGrid> or <PUnstructuredGrid>),
//      and (name, value) strings.
// Out: the same text with one string array per pair, one tuple each, in the
//      dataset's <FieldData> (created right after the dataset's start tag if
//      absent): <DataArray type="String" Name="..." NumberOfTuples="1"
//      format="ascii"> with the value as byte codes ending in 0, the ASCII
//      form VTK's XML readers read (vtkStringArray). ParaView shows them under
//      Information > Data Arrays (field data).
// Throws std::invalid_argument if the text has no VTKFile dataset element.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "puncture/io/provenance.hpp"

namespace puncture::io {

std::string add_vtk_xml_field_data(const std::string& vtk_xml,
                                   const std::vector<std::pair<std::string, std::string>>& fields);

/// add_vtk_xml_field_data with "provenance_<key>" for every provenance field
/// (provenance_command, provenance_program_version, ...) and
/// "coordinate_unit" = coordinate_unit (e.g. "m") when not empty.
std::string add_provenance_field_data(const std::string& vtk_xml, const Provenance& provenance,
                                      const std::string& coordinate_unit = "m");

/// "<!-- provenance: command: ... | program_version: ... | ... -->" ("--"
/// inside values written "- -", as XML requires).
std::string provenance_xml_comment(const Provenance& provenance);

/// The comment inserted after the XML declaration (at the start without one):
/// for XML files without field data of their own (.pvd, .pvtu).
std::string add_provenance_comment(const std::string& xml, const Provenance& provenance);

/// The (name, value) pairs add_provenance_field_data writes; the VTK writers of
/// validation/io store the same names.
std::vector<std::pair<std::string, std::string>> provenance_field_data(const Provenance& provenance,
                                                                        const std::string& coordinate_unit = "m");

}  // namespace puncture::io
