#include <puncture/io/pvd.hpp>

#include <puncture/io/atomic_file.hpp>
#include <puncture/io/output_session.hpp>
#include <puncture/io/vtk_xml_field_data.hpp>
#include <puncture/io/xml_escape.hpp>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace puncture::io {

std::string pvd_document(const std::vector<PvdEntry>& entries, const Provenance* provenance,
                         const PvdFormat& format) {
  std::string out = "<?xml version=\"1.0\"?>\n";
  if (!format.comment.empty()) out += "<!--" + format.comment + "-->\n";
  if (provenance) out += provenance_xml_comment(*provenance) + "\n";
  out += "<VTKFile type=\"Collection\" version=\"0.1\"";
  if (!format.byte_order_attribute.empty()) out += " " + format.byte_order_attribute + "=\"LittleEndian\"";
  out += ">\n  <Collection>\n";
  char buffer[64];
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const PvdEntry& e = entries[i];
    const std::string where = "write_pvd: entry " + std::to_string(i);
    if (!std::isfinite(e.time_s)) throw std::invalid_argument(where + ": time_s is not finite");
    if (e.part < 0) throw std::invalid_argument(where + ": part must be >= 0");
    if (e.file.empty()) throw std::invalid_argument(where + ": empty file name");
    std::string time;
    if (format.time_digits > 0) {
      const int n = std::snprintf(buffer, sizeof buffer, "%.*g", format.time_digits, e.time_s);
      time.assign(buffer, static_cast<std::size_t>(n));
    } else {
      const auto res = std::to_chars(buffer, buffer + sizeof(buffer), e.time_s);
      time.assign(buffer, res.ptr);
    }
    out += "    <DataSet timestep=\"" + time + "\"" + (format.group_attribute ? " group=\"\"" : "") + " part=\"" +
           std::to_string(e.part) + "\" file=\"" + xml_escape(e.file) +
           "\"/>\n";
  }
  out += "  </Collection>\n</VTKFile>\n";
  return out;
}

void write_pvd(OutputSession& session, const std::string& relative_name, const std::vector<PvdEntry>& entries,
               const Provenance* provenance) {
  session.write_text(relative_name, pvd_document(entries, provenance));
}

void write_pvd_file(const std::filesystem::path& path, const std::vector<PvdEntry>& entries,
                    const Provenance* provenance, const PvdFormat& format) {
  write_file_atomically(path, pvd_document(entries, provenance, format));
}

}  // namespace puncture::io
