// Provenance: every field filled, the git revision is the source tree's
// HEAD (generated at build time, not at configure time), and the
// serialisations (CSV comment lines, .pvd comment, VTK XML field data).
#include <gtest/gtest.h>

#include <cstdio>
#include <regex>
#include <string>

#include "puncture/io/provenance.hpp"
#include "puncture/io/provenance_json.hpp"
#include "puncture/io/pvd.hpp"
#include "puncture/io/vtk_xml_field_data.hpp"

namespace puncture::io {
namespace {

std::string shell(const std::string& command) {
  std::string out;
  if (FILE* p = ::popen(command.c_str(), "r")) {
    char buffer[256];
    while (std::fgets(buffer, sizeof buffer, p)) out += buffer;
    ::pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

TEST(Provenance, FieldsAreFilledAndTheRevisionIsTheSourceTreesHead) {
  const Provenance p = make_provenance("puncture run x.json");
  EXPECT_EQ(p.command, "puncture run x.json");
  EXPECT_FALSE(p.program_version.empty());
  EXPECT_TRUE(std::regex_match(p.date_utc, std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ)"))) << p.date_utc;
  EXPECT_NE(p.machine.find("cores"), std::string::npos) << p.machine;
  const std::string head =
      shell("git -C '" + std::string(PUNCTURE_SOURCE_DIR) + "' rev-parse --short=7 HEAD 2>/dev/null");
  if (head.empty()) {
    EXPECT_EQ(std::string(git_revision()), "unknown");  // not a git checkout
  } else {
    // "<HEAD>" or "<HEAD>-dirty": the revision of the tree that was built.
    EXPECT_EQ(std::string(git_revision()).substr(0, head.size()), head) << git_revision();
  }
  const nlohmann::json j = provenance_json(p);
  EXPECT_EQ(j.at("git_revision"), git_revision());
  EXPECT_EQ(j.size(), 5u);
  EXPECT_EQ(provenance_comment_lines(p).substr(0, 30), "# command: puncture run x.json");
}

TEST(Provenance, PvdCarriesItInAnXmlComment) {
  Provenance p = make_provenance("puncture run --weird -- name");
  const std::string doc = pvd_document({{0.5, 0, "frames/a.vtp"}}, &p);
  const auto open = doc.find("<!-- provenance: command: puncture run --weird");
  EXPECT_EQ(open, std::string::npos) << "'--' must not appear inside an XML comment";
  EXPECT_NE(doc.find("<!-- provenance: command: puncture run - -weird - - name | program_version:"), std::string::npos)
      << doc;
  EXPECT_NE(doc.find("timestep=\"0.5\""), std::string::npos);
  EXPECT_EQ(pvd_document({{0.5, 0, "a.vtp"}}).find("provenance"), std::string::npos);
}

TEST(Provenance, FieldDataIsInsertedIntoVtkXmlText) {
  const std::string vtu =
      "<?xml version=\"1.0\" ?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n<UnstructuredGrid>\n"
      "<Piece NumberOfPoints=\"0\" NumberOfCells=\"0\"></Piece>\n</UnstructuredGrid>\n</VTKFile>\n";
  const Provenance p{"c", "v", "r", "d", "m"};
  const std::string out = add_provenance_field_data(vtu, p);
  const auto field = out.find("<FieldData>");
  ASSERT_NE(field, std::string::npos) << out;
  EXPECT_LT(out.find("<UnstructuredGrid>"), field);
  EXPECT_LT(field, out.find("<Piece"));
  // "c" = 99, then the terminating 0.
  EXPECT_NE(out.find("Name=\"provenance_command\" NumberOfTuples=\"1\" format=\"ascii\">\n        99 0"),
            std::string::npos)
      << out;
  EXPECT_NE(out.find("Name=\"coordinate_unit\""), std::string::npos);
  // An existing <FieldData> block is extended, not duplicated.
  const std::string twice = add_vtk_xml_field_data(out, {{"extra", "x"}});
  EXPECT_EQ(twice.find("<FieldData>", field + 1), std::string::npos);
  EXPECT_NE(twice.find("Name=\"extra\""), std::string::npos);
  EXPECT_THROW(add_vtk_xml_field_data("<html/>", {}), std::invalid_argument);
}

TEST(Provenance, WithoutABlasLoadedTheMachineSummaryEndsWithTheCores) {
  // This test program links no BLAS (the comparison suite checks the other case).
  EXPECT_EQ(blas_library(), "");
  const std::string m = machine_summary();
  EXPECT_EQ(m.substr(m.size() - 7), " cores)") << m;
}

}  // namespace
}  // namespace puncture::io
