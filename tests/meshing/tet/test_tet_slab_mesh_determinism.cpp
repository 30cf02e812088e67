// Determinism of the production tetrahedral mesh across processes: the test
// builds the mesh of one scene with the production options (sliver exudation
// on) in this process and in two fresh processes of this same executable (a
// new address-space layout each), one of which first allocates and frees
// blocks of random sizes so that CGAL's cells and vertices land at other
// addresses in another order. The three digests of the vertex coordinates
// (bit patterns), the tetrahedra (vertex indices, in order), the layer ids and
// the needle-column flags must be equal.
//
// Child mode: when the environment variable PUNCTURE_TET_MESH_DIGEST_CHILD is
// set (to the number of garbage bytes to allocate first), the executable
// builds the mesh, prints one line "tet-mesh-digest: ..." and exits 0 before
// any test runs (a GoogleTest environment's SetUp).
#include <gtest/gtest.h>

#include <unistd.h>

#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "puncture/meshing/tet_slab_mesh.hpp"
#include "tet_test_scenes.hpp"

namespace puncture::meshing {
namespace {

constexpr const char* kChildVariable = "PUNCTURE_TET_MESH_DIGEST_CHILD";
constexpr const char* kDigestPrefix = "tet-mesh-digest: ";

/// FNV-1a (64 bit) over raw bytes, chained through `hash`.
std::uint64_t fnv1a(const void* data, std::size_t bytes, std::uint64_t hash) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) hash = (hash ^ p[i]) * 0x100000001b3ULL;
  return hash;
}

/// "vertices N tetrahedra M digest H": H hashes every coordinate's bit
/// pattern, every tetrahedron's four vertex indices in order, its layer id and
/// its needle-column flag.
std::string describe_mesh(const meshing::TetMesh& mesh) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (Eigen::Index a = 0; a < mesh.points_m.cols(); ++a)
    for (int i = 0; i < 3; ++i) {
      const double x = mesh.points_m(i, a);
      hash = fnv1a(&x, sizeof x, hash);
    }
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    const int row[6] = {mesh.tets[t][0], mesh.tets[t][1], mesh.tets[t][2],
                        mesh.tets[t][3], mesh.layer[t],   mesh.needle_column[t]};
    hash = fnv1a(row, sizeof row, hash);
  }
  std::ostringstream out;
  out << "vertices " << mesh.node_count() << " tetrahedra " << mesh.tet_count() << " digest " << std::hex << hash;
  return out.str();
}

/// The scene and the production options (those `puncture compare` uses).
meshing::TetMesh production_mesh() {
  const Scene scene = testing::small_slab_scene();
  return build_tet_slab_mesh(scene, tet_slab_mesh_options(scene));
}

/// Child mode: allocate `garbage_bytes` in blocks of random sizes, free every
/// other block (holes of random sizes in the heap), mesh, print, exit.
class DigestChild : public ::testing::Environment {
 public:
  void SetUp() override {
    const char* value = std::getenv(kChildVariable);
    if (value == nullptr) return;
    const std::size_t garbage_bytes = std::strtoull(value, nullptr, 10);
    std::mt19937_64 random(std::random_device{}());
    std::vector<std::unique_ptr<char[]>> blocks;
    for (std::size_t used = 0; used < garbage_bytes;) {
      const std::size_t bytes = 1 + random() % 4096;
      blocks.emplace_back(new char[bytes]);
      std::memset(blocks.back().get(), 0x5a, bytes);
      used += bytes;
    }
    for (std::size_t i = 0; i < blocks.size(); i += 2) blocks[i].reset();
    const std::string line = kDigestPrefix + describe_mesh(production_mesh());
    std::printf("%s\n", line.c_str());
    std::fflush(stdout);
    std::_Exit(0);
  }
};
[[maybe_unused]] ::testing::Environment* const kDigestChild = ::testing::AddGlobalTestEnvironment(new DigestChild);

/// Runs this executable in child mode and returns its digest line (without
/// the prefix); fails the test if the child fails or prints none.
std::string mesh_in_fresh_process(std::size_t garbage_bytes) {
  char executable[PATH_MAX] = {};
  const ssize_t length = readlink("/proc/self/exe", executable, sizeof executable - 1);
  EXPECT_GT(length, 0) << "cannot read /proc/self/exe";
  if (length <= 0) return "";
  const std::string command =
      std::string(kChildVariable) + "=" + std::to_string(garbage_bytes) + " '" + executable + "' 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  EXPECT_NE(pipe, nullptr) << command;
  if (pipe == nullptr) return "";
  std::string digest, output;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) {
    const std::string line(buffer);
    output += line;
    if (line.rfind(kDigestPrefix, 0) == 0) digest = line.substr(std::strlen(kDigestPrefix));
  }
  const int status = pclose(pipe);
  EXPECT_EQ(status, 0) << command << " failed:\n" << output;
  EXPECT_FALSE(digest.empty()) << command << " printed no digest:\n" << output;
  while (!digest.empty() && (digest.back() == '\n' || digest.back() == '\r')) digest.pop_back();
  return digest;
}

TEST(TetSlabMeshDeterminism, SameMeshInSeparateProcessesWithProductionOptions) {
  const Scene scene = testing::small_slab_scene();
  ASSERT_TRUE(tet_slab_mesh_options(scene).exude_slivers) << "the production options exude slivers";
  const std::string here = describe_mesh(production_mesh());
  std::mt19937_64 random(std::random_device{}());
  const std::size_t garbage_bytes = (1u << 20) + random() % (16u << 20);  // 1-17 MB
  const std::string plain_child = mesh_in_fresh_process(0);
  const std::string cluttered_child = mesh_in_fresh_process(garbage_bytes);
  EXPECT_EQ(plain_child, here) << "a fresh process meshed the same scene differently";
  EXPECT_EQ(cluttered_child, here) << "a fresh process with " << garbage_bytes
                                   << " bytes of heap clutter meshed the same scene differently";
}

TEST(TetSlabMeshDeterminism, DigestSeesOneUlpAndOneSwappedVertex) {
  // The comparison above is only as good as the digest: it must change when
  // one coordinate moves by one ulp or one tetrahedron lists its vertices in
  // another order. Two tetrahedra sharing the face (0, 1, 2).
  meshing::TetMesh mesh;
  mesh.points_m.resize(3, 5);
  mesh.points_m << 0, 1e-3, 0, 0, 0,  //
      0, 0, 1e-3, 0, 0,               //
      0, 0, 0, 1e-3, -1e-3;
  mesh.tets = {Eigen::Vector4i(0, 1, 2, 3), Eigen::Vector4i(0, 2, 1, 4)};
  mesh.layer = {0, 1};
  mesh.needle_column = {1, 0};
  const std::string original = describe_mesh(mesh);
  meshing::TetMesh moved = mesh;
  moved.points_m(2, 3) = std::nextafter(moved.points_m(2, 3), 1.0);
  EXPECT_NE(describe_mesh(moved), original);
  meshing::TetMesh swapped = mesh;
  std::swap(swapped.tets[1][0], swapped.tets[1][1]);
  EXPECT_NE(describe_mesh(swapped), original);
  meshing::TetMesh relabelled = mesh;
  relabelled.needle_column[1] = 1;
  EXPECT_NE(describe_mesh(relabelled), original);
  EXPECT_EQ(describe_mesh(mesh), original);
}

}  // namespace
}  // namespace puncture::meshing
