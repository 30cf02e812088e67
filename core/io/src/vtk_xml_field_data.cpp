#include "puncture/io/vtk_xml_field_data.hpp"

#include "puncture/io/xml_escape.hpp"

#include <stdexcept>

namespace puncture::io {

namespace {
std::string string_array(const std::string& name, const std::string& value) {
  std::string out = "      <DataArray type=\"String\" Name=\"" + xml_escape(name, /*escape_apostrophe=*/false) +
                    "\" NumberOfTuples=\"1\" format=\"ascii\">\n        ";
  for (unsigned char c : value) out += std::to_string(static_cast<int>(c)) + " ";
  out += "0\n      </DataArray>\n";
  return out;
}
}  // namespace

std::string add_vtk_xml_field_data(const std::string& text,
                                   const std::vector<std::pair<std::string, std::string>>& fields) {
  const std::size_t vtkfile = text.find("<VTKFile");
  if (vtkfile == std::string::npos) throw std::invalid_argument("add_vtk_xml_field_data: no <VTKFile> element");
  const std::size_t vtkfile_end = text.find('>', vtkfile);
  // The dataset element: the first start tag after <VTKFile ...>.
  std::size_t dataset = text.find('<', vtkfile_end);
  while (dataset != std::string::npos && (text.compare(dataset, 4, "<!--") == 0 || text.compare(dataset, 2, "<?") == 0))
    dataset = text.find('<', text.find('>', dataset));
  if (vtkfile_end == std::string::npos || dataset == std::string::npos || text[dataset + 1] == '/')
    throw std::invalid_argument("add_vtk_xml_field_data: no dataset element inside <VTKFile>");
  const std::size_t dataset_end = text.find('>', dataset);
  if (dataset_end == std::string::npos) throw std::invalid_argument("add_vtk_xml_field_data: unterminated tag");
  std::string arrays;
  for (const auto& [name, value] : fields) arrays += string_array(name, value);

  std::size_t after = text.find_first_not_of(" \t\r\n", dataset_end + 1);
  std::string out = text;
  if (after != std::string::npos && text.compare(after, 11, "<FieldData>") == 0) {
    out.insert(after + 11, "\n" + arrays);
  } else {
    out.insert(dataset_end + 1, "\n    <FieldData>\n" + arrays + "    </FieldData>");
  }
  return out;
}

std::string provenance_xml_comment(const Provenance& provenance) {
  std::string text;
  for (const auto& [key, value] : provenance_fields(provenance)) text += (text.empty() ? "" : " | ") + key + ": " + value;
  for (std::size_t p = text.find("--"); p != std::string::npos; p = text.find("--", p)) text.replace(p, 2, "- -");
  if (!text.empty() && text.back() == '-') text += ' ';
  return "<!-- provenance: " + text + " -->";
}

std::string add_provenance_comment(const std::string& xml, const Provenance& provenance) {
  std::size_t at = 0;
  if (xml.compare(0, 5, "<?xml") == 0) {
    const std::size_t end = xml.find("?>");
    if (end != std::string::npos) at = end + 2;
  }
  std::string out = xml;
  out.insert(at, (at ? "\n" : "") + provenance_xml_comment(provenance) + (at ? "" : "\n"));
  return out;
}

std::vector<std::pair<std::string, std::string>> provenance_field_data(const Provenance& provenance,
                                                                        const std::string& coordinate_unit) {
  std::vector<std::pair<std::string, std::string>> fields;
  for (const auto& [key, value] : provenance_fields(provenance)) fields.emplace_back("provenance_" + key, value);
  if (!coordinate_unit.empty()) fields.emplace_back("coordinate_unit", coordinate_unit);
  return fields;
}

std::string add_provenance_field_data(const std::string& text, const Provenance& provenance,
                                      const std::string& coordinate_unit) {
  return add_vtk_xml_field_data(text, provenance_field_data(provenance, coordinate_unit));
}

}  // namespace puncture::io
