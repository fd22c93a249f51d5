// Round trips through every format, polygon handling and each documented failure of mesh/mesh_io.h.
#include "mesh/mesh_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "tests/support/test_support.h"

namespace raysift::mesh {
namespace {

/// A closed tetrahedron with positions that are not short decimals, to catch precision loss.
TriMesh tetrahedron() {
  TriMesh m;
  m.positions = {{0.1f, 0.2f, 0.3f}, {1.0f / 3.0f, 0.0f, 0.0f}, {0.0f, 2.0f / 7.0f, 0.0f}, {0.0f, 0.0f, 1e-3f}};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

class MeshIoFormat : public ::testing::TestWithParam<std::pair<std::string, bool>> {};

TEST_P(MeshIoFormat, RoundTripIsExact) {
  const auto [ext, binary] = GetParam();
  const std::string path = test::make_temp_dir("mesh_io") + "/tet" + ext;
  const TriMesh in = tetrahedron();
  write_mesh(path, in, {binary});
  const TriMesh out = read_mesh(path);
  ASSERT_EQ(out.positions.size(), in.positions.size());
  for (std::size_t i = 0; i < in.positions.size(); ++i) EXPECT_EQ(out.positions[i], in.positions[i]) << i;
  EXPECT_EQ(out.triangles, in.triangles);
}

INSTANTIATE_TEST_SUITE_P(Formats, MeshIoFormat,
                         ::testing::Values(std::make_pair(std::string(".ply"), true),
                                           std::make_pair(std::string(".ply"), false),
                                           std::make_pair(std::string(".obj"), false),
                                           std::make_pair(std::string(".off"), false)));

TEST(MeshIo, QuadsAreFanTriangulated) {
  const std::string path = test::make_temp_dir("mesh_io") + "/quad.off";
  write_text(path, "OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n4 0 1 2 3\n3 1 4 2\n");
  const TriMesh m = read_mesh(path);
  ASSERT_EQ(m.triangle_count(), 3u);
  EXPECT_EQ(m.triangles[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(m.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(m.triangles[2], (std::array<std::uint32_t, 3>{1, 4, 2}));
  EXPECT_THROW(read_mesh(path, {/*triangulate_polygons=*/false}), InvalidInput);
}

TEST(MeshIo, MissingFileIsIoError) {
  EXPECT_THROW(read_mesh(test::make_temp_dir("mesh_io") + "/absent.ply"), IoError);
}

TEST(MeshIo, UnknownExtensionIsIoError) {
  const std::string dir = test::make_temp_dir("mesh_io");
  write_text(dir + "/m.stl", "solid x\nendsolid x\n");
  EXPECT_THROW(read_mesh(dir + "/m.stl"), IoError);
  EXPECT_THROW(write_mesh(dir + "/m.stl", tetrahedron()), IoError);
}

TEST(MeshIo, MalformedFileIsIoError) {
  const std::string path = test::make_temp_dir("mesh_io") + "/bad.ply";
  write_text(path, "this is not a ply file\n");
  EXPECT_THROW(read_mesh(path), IoError);
}

// Regression tests for two fuzz findings (tests/fuzz/corpus/{ply,obj}): before the pre-check, the first input hung
// OpenMesh's PLY reader forever and the second aborted the process in an OpenMesh assert.
std::string io_error_of(const std::string& path) {
  try {
    read_mesh(path);
  } catch (const IoError& e) {
    return e.what();
  }
  return "no IoError";
}

TEST(MeshIo, PlyHeaderWithoutEndHeaderIsIoErrorNotAHang) {
  const std::string path = test::make_temp_dir("mesh_io") + "/no_end.ply";
  write_text(path, test::read_text(RAYSIFT_SOURCE_DIR "/tests/fuzz/corpus/ply/timeout_no_end_header.ply"));
  EXPECT_NE(io_error_of(path).find(path + ":5: malformed PLY header line"), std::string::npos) << io_error_of(path);
  write_text(path, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n");
  const std::string msg = io_error_of(path);
  EXPECT_NE(msg.find(path + ": malformed PLY: the header has no 'end_header'"), std::string::npos) << msg;
}

TEST(MeshIo, MalformedPlyHeaderLineIsIoErrorNotACrash) {
  const std::string path = test::make_temp_dir("mesh_io") + "/bad_property.ply";
  write_text(path, test::read_text(RAYSIFT_SOURCE_DIR "/tests/fuzz/corpus/ply/crash_malformed_property.ply"));
  const std::string msg = io_error_of(path);
  EXPECT_NE(msg.find(path + ":3: malformed PLY header line 'elemen 1.0e'"), std::string::npos) << msg;
  write_text(path, test::read_text(RAYSIFT_SOURCE_DIR "/tests/fuzz/corpus/ply/crash_property_before_element.ply"));
  EXPECT_NE(io_error_of(path).find(path + ":4: malformed PLY header line"), std::string::npos) << io_error_of(path);
  write_text(path, test::read_text(RAYSIFT_SOURCE_DIR "/tests/fuzz/corpus/ply/timeout_bad_version.ply"));
  EXPECT_NE(io_error_of(path).find(path + ":2: malformed PLY header line"), std::string::npos) << io_error_of(path);
}

TEST(MeshIo, AsciiPlyFaceCountOutOfRangeIsIoErrorNotAnOutOfMemory) {
  const std::string path = test::make_temp_dir("mesh_io") + "/count.ply";
  write_text(path, test::read_text(RAYSIFT_SOURCE_DIR "/tests/fuzz/corpus/ply/negative_face_count.ply"));
  std::string msg = io_error_of(path);
  EXPECT_NE(msg.find(path + ":15: face 1: '-4' is not a valid uchar"), std::string::npos) << msg;
  // Two face lines merged into one: OpenMesh read "2-4" as 2 then -4 and allocated 3 GB (CI fuzz run).
  write_text(path, test::read_text(RAYSIFT_SOURCE_DIR "/tests/fuzz/corpus/ply/oom_merged_face_lines.ply"));
  msg = io_error_of(path);
  EXPECT_NE(msg.find(path + ":14: face 0: '2-4' is not a valid int"), std::string::npos) << msg;
  // Vertices with negative coordinates before the faces are not face lines; a well-formed file still reads.
  write_text(path, "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face 1\nproperty list uchar int vertex_indices\nend_header\n-1 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(read_mesh(path).triangle_count(), 1u);
}

const std::string kTriangleHeader =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 1\nproperty list uchar int vertex_indices\nend_header\n";

TEST(MeshIo, PlyCountsLargerThanTheFileAreIoErrorsBeforeAllocating) {
  const std::string path = test::make_temp_dir("mesh_io") + "/huge.ply";
  write_text(path, "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                   "property float y\nproperty float z\nend_header\n0123456789");
  EXPECT_NE(io_error_of(path).find("PLY element 'vertex' declares 4000000000 items, more than the 10 bytes"),
            std::string::npos) << io_error_of(path);
  write_text(path, kTriangleHeader + "0 0 0 1 0 0 0 1 0 200 0 1 2\n");
  EXPECT_NE(io_error_of(path).find(":10: face 0: list 'vertex_indices' of 200 items is longer than the file"),
            std::string::npos) << io_error_of(path);
}

TEST(MeshIo, TruncatedOrMalformedPlyBodyIsIoErrorNamingTheLine) {
  const std::string path = test::make_temp_dir("mesh_io") + "/body.ply";
  write_text(path, kTriangleHeader + "0 0 0\n1 0 0\n0 1 0\n3 0 1\n");
  EXPECT_NE(io_error_of(path).find(path + ":14: face 0: the file ends inside it"), std::string::npos)
      << io_error_of(path);
  write_text(path, kTriangleHeader + "0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n");
  EXPECT_NE(io_error_of(path).find(path + ":11: vertex 1: 'zero' is not a valid float"), std::string::npos)
      << io_error_of(path);
  write_text(path, kTriangleHeader + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n");
  EXPECT_NE(io_error_of(path).find(path + ":13: face 0: 2 corners; a face needs at least 3"), std::string::npos)
      << io_error_of(path);
}

TEST(MeshIo, PlyReadsBigEndianExtraPropertiesAndSkippedElements) {
  // Big-endian double positions with a colour list, an unknown element between vertices and faces, and a face
  // with an extra scalar after its indices: the reader must skip everything but x, y, z and the indices.
  const std::string path = test::make_temp_dir("mesh_io") + "/be.ply";
  std::ofstream f(path, std::ios::binary);
  f << "ply\nformat binary_big_endian 1.0\ncomment made by hand\nelement vertex 3\nproperty double x\n"
       "property list uchar uchar rgb\nproperty double y\nproperty double z\nelement material 2\n"
       "property short shine\nelement face 1\nproperty list uchar uint vertex_indices\nproperty float quality\n"
       "end_header\n";
  const auto put = [&](const void* value, int bytes) {
    const auto* b = static_cast<const unsigned char*>(value);
    for (int i = bytes - 1; i >= 0; --i) f.put(char(b[i]));  // host (little-endian) -> big-endian
  };
  const double xyz[3][3] = {{0.1, -2.5, 3}, {1e-3, 4, 0}, {7, 8, 9}};
  for (const auto& v : xyz) {
    put(&v[0], 8);
    f.put(char(2)).put(char(255)).put(char(0));
    put(&v[1], 8);
    put(&v[2], 8);
  }
  const std::int16_t shine = 5;
  for (int m = 0; m < 2; ++m) put(&shine, 2);
  f.put(char(3));
  for (std::uint32_t i : {2u, 0u, 1u}) put(&i, 4);
  const float quality = 0.5f;
  put(&quality, 4);
  f.close();
  const TriMesh m = read_mesh(path);
  ASSERT_EQ(m.positions.size(), 3u);
  for (int v = 0; v < 3; ++v)
    EXPECT_EQ(m.positions[v], (Vec3f{float(xyz[v][0]), float(xyz[v][1]), float(xyz[v][2])})) << v;
  ASSERT_EQ(m.triangle_count(), 1u);
  EXPECT_EQ(m.triangles[0], (std::array<std::uint32_t, 3>{2, 0, 1}));
}

TEST(MeshIo, OffCountsAndNumbersAreCheckedNamingTheLine) {
  const std::string path = test::make_temp_dir("mesh_io") + "/bad.off";
  // OpenMesh allocated gigabytes for this one (fuzz finding): a negative vertex count.
  write_text(path, test::read_text(RAYSIFT_SOURCE_DIR "/tests/fuzz/corpus/off/oom_negative_vertex_count.off"));
  EXPECT_NE(io_error_of(path).find(path + ":2: vertex count '-4' is not an integer in [0, 4]"), std::string::npos)
      << io_error_of(path);
  write_text(path, "OFF\n3 1000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_NE(io_error_of(path).find(path + ":2: face count '1000000000' is not an integer in [0, 1]"),
            std::string::npos) << io_error_of(path);
  write_text(path, "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n");
  EXPECT_NE(io_error_of(path).find(path + ":4: expected 3 numbers, found 2"), std::string::npos) << io_error_of(path);
  write_text(path, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n");
  EXPECT_NE(io_error_of(path).find(path + ":6: vertex index '-1'"), std::string::npos) << io_error_of(path);
  write_text(path, "OFF BINARY\n");
  EXPECT_NE(io_error_of(path).find(path + ":1: binary OFF is not supported"), std::string::npos) << io_error_of(path);
}

TEST(MeshIo, OffWithCommentsColoursAndCountsOnTheKeywordLineReads) {
  const std::string path = test::make_temp_dir("mesh_io") + "/c.off";
  write_text(path, "# a comment\nCOFF 3 1 3\n\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255 # red\n0 1 0 0 0 255 255\n"
                   "3 2 1 0 0.5 0.5 0.5\n");
  const TriMesh m = read_mesh(path);
  ASSERT_EQ(m.positions.size(), 3u);
  EXPECT_EQ(m.positions[1], (Vec3f{1, 0, 0}));
  ASSERT_EQ(m.triangle_count(), 1u);
  EXPECT_EQ(m.triangles[0], (std::array<std::uint32_t, 3>{2, 1, 0}));
}

TEST(MeshIo, PlyElementDeclaredTwiceIsIoErrorNotAHang) {
  const std::string path = test::make_temp_dir("mesh_io") + "/twice.ply";
  write_text(path, test::read_text(RAYSIFT_SOURCE_DIR "/tests/fuzz/corpus/ply/timeout_duplicate_elements.ply"));
  const std::string msg = io_error_of(path);
  EXPECT_NE(msg.find(path + ":6: PLY element 'vertex' declared twice"), std::string::npos) << msg;
}

TEST(MeshIo, ObjFaceCornerWithoutVertexIndexIsIoErrorNotAnAbort) {
  const std::string path = test::make_temp_dir("mesh_io") + "/corner.obj";
  write_text(path, test::read_text(RAYSIFT_SOURCE_DIR "/tests/fuzz/corpus/obj/crash_corner_without_vertex.obj"));
  const std::string msg = io_error_of(path);
  EXPECT_NE(msg.find(path + ":1: face corner '/1/1'"), std::string::npos) << msg;
  // Negative (relative) indices and all slash forms stay valid.
  write_text(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf -3/1/1 -2//1 -1/1\n");
  EXPECT_EQ(read_mesh(path).triangle_count(), 1u);
}

TEST(MeshIo, FileWithoutFacesIsInvalidInput) {
  const std::string path = test::make_temp_dir("mesh_io") + "/points.off";
  write_text(path, "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n");
  EXPECT_THROW(read_mesh(path), InvalidInput);
}

TEST(MeshIo, NonFiniteVertexIsInvalidInput) {
  // Binary PLY stores the NaN bit pattern verbatim, so the check after parsing must catch it.
  const std::string path = test::make_temp_dir("mesh_io") + "/nan.ply";
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  std::ofstream f(path, std::ios::binary);
  f << header;
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, std::nanf(""), 0};
  f.write(reinterpret_cast<const char*>(v), sizeof v);
  const unsigned char n = 3;
  const int idx[3] = {0, 1, 2};
  f.write(reinterpret_cast<const char*>(&n), 1);
  f.write(reinterpret_cast<const char*>(idx), sizeof idx);
  f.close();
  try {
    read_mesh(path);
    FAIL() << "expected InvalidInput";
  } catch (const InvalidInput& e) {
    EXPECT_NE(std::string(e.what()).find("vertex 2"), std::string::npos) << e.what();
  }
}

TEST(MeshIo, WriteRejectsBadMeshWithoutLeavingAFile) {
  const std::string path = test::make_temp_dir("mesh_io") + "/bad.ply";
  TriMesh m = tetrahedron();
  m.triangles.push_back({0, 1, 9});
  EXPECT_THROW(write_mesh(path, m), InvalidInput);
  m = tetrahedron();
  m.positions[1].y = std::numeric_limits<float>::infinity();
  EXPECT_THROW(write_mesh(path, m), InvalidInput);
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace raysift::mesh
