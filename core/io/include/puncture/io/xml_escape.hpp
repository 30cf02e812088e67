// xml_escape.hpp: text made safe for an XML attribute value or element text.
//
// In:  any text.
// Out: the text with & < > " written as &amp; &lt; &gt; &quot;, and ' as
//      &apos; unless escape_apostrophe is false (attribute values in double
//      quotes do not need it; the field-data array names of
//      vtk_xml_field_data.hpp keep their apostrophes as they always did).
// Used by the .pvd writer (file names) and the VTK XML field data (names).
#pragma once

#include <string>

namespace puncture::io {

std::string xml_escape(const std::string& text, bool escape_apostrophe = true);

}  // namespace puncture::io
