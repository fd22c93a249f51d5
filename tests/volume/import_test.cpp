#include "volume/import.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>
#include <fstream>
#include <vector>

#include "core/errors.h"
#include "tests/support/test_support.h"

namespace raysift::volume {
namespace {

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

std::uint32_t crc32(const std::string& s) {
  std::uint32_t c = 0xffffffffu;
  for (unsigned char b : s) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return ~c;
}

/// A valid gzip stream made of uncompressed ("stored") deflate blocks (RFC 1951 §3.2.4, RFC 1952), built here
/// without zlib so the test checks the importer against an independent encoder.
std::string gzip_stored(const std::string& data) {
  std::string out("\x1f\x8b\x08\x00\x00\x00\x00\x00\x00\xff", 10);
  std::size_t pos = 0;
  do {
    const std::size_t n = std::min<std::size_t>(data.size() - pos, 65535);
    const bool last = pos + n == data.size();
    out.push_back(char(last ? 1 : 0));
    const std::uint16_t len = std::uint16_t(n), nlen = std::uint16_t(~len);
    out.append(reinterpret_cast<const char*>(&len), 2).append(reinterpret_cast<const char*>(&nlen), 2);
    out.append(data, pos, n);
    pos += n;
  } while (pos < data.size());
  const std::uint32_t crc = crc32(data), size = std::uint32_t(data.size());
  out.append(reinterpret_cast<const char*>(&crc), 4).append(reinterpret_cast<const char*>(&size), 4);
  return out;
}

std::string be16(const std::vector<std::uint16_t>& v) {
  std::string s;
  for (std::uint16_t x : v) s.push_back(char(x >> 8)), s.push_back(char(x & 0xff));
  return s;
}

std::string le_floats(const std::vector<float>& v) {
  std::string s(v.size() * 4, '\0');
  std::memcpy(s.data(), v.data(), s.size());
  return s;
}

template <typename F>
std::string invalid_input_message(F&& f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  ADD_FAILURE() << "InvalidInput not thrown";
  return "";
}

/// A mostly-empty 16x12x10 u8 volume: a few scattered non-zero voxels.
std::string sparse_u8(std::uint64_t& nonzero) {
  std::string s(16 * 12 * 10, '\0');
  nonzero = 0;
  for (std::size_t i = 0; i < s.size(); i += 37) s[i] = char(1 + i % 200), ++nonzero;
  return s;
}

TEST(ImportRaw, SparseImportKeepsExactlyTheNonBackgroundVoxels) {
  const std::string path = test::make_temp_dir("raw_sparse") + "/v.raw";
  std::uint64_t nonzero = 0;
  const std::string bytes = sparse_u8(nonzero);
  write_file(path, bytes);
  const Volume v = import_raw(path, {{16, 12, 10}, ScalarType::U8, Endian::Little});
  EXPECT_EQ(v.active_voxel_count(), nonzero);
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    const Vec3i ijk(int(i % 16), int(i / 16 % 12), int(i / 192));
    ASSERT_EQ(v.value_at(ijk), float(static_cast<unsigned char>(bytes[i]))) << i;
  }
}

TEST(ImportRaw, IdenticalForOneAndTwoThreads) {
  const std::string path = test::make_temp_dir("raw_threads") + "/v.raw";
  std::string bytes(40 * 30 * 20, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = char((i * 2654435761u >> 13) % 7 == 0 ? 1 + i % 250 : 0);
  write_file(path, bytes);
  auto run = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    return import_raw(path, {{40, 30, 20}, ScalarType::U8, Endian::Little});
  };
  const Volume a = run(1), b = run(2);
  ASSERT_EQ(a.active_voxel_count(), b.active_voxel_count());
  for (std::size_t i = 0; i < bytes.size(); ++i) {
    const Vec3i ijk(int(i % 40), int(i / 40 % 30), int(i / 1200));
    ASSERT_EQ(a.value_at(ijk), b.value_at(ijk)) << i;
  }
}

TEST(ImportRaw, BigEndianU16ReadsBackExactly) {
  const std::string dir = test::make_temp_dir("raw_be");
  const std::vector<std::uint16_t> values = {0, 1, 0x0102, 0xfffe, 1000, 65535, 256, 255};
  write_file(dir + "/be.raw", be16(values));
  const Volume v = import_raw(dir + "/be.raw", {{2, 2, 2}, ScalarType::U16, Endian::Big});
  for (int n = 0; n < 8; ++n) EXPECT_EQ(v.value_at({n & 1, (n >> 1) & 1, n >> 2}), float(values[n])) << n;
  // The same bytes read as little endian swap each pair: 0x0102 -> 0x0201.
  const Volume le = import_raw(dir + "/be.raw", {{2, 2, 2}, ScalarType::U16, Endian::Little});
  EXPECT_EQ(le.value_at({0, 1, 0}), float(0x0201));
}

TEST(ImportRaw, FloatToleranceAndSpacing) {
  const std::string path = test::make_temp_dir("raw_f32") + "/f.raw";
  write_file(path, le_floats({0.0f, 0.004f, -0.02f, 1.5f, 0.0f, 0.009f, 2.0f, 0.0f}));
  ImportOptions o;
  o.tolerance = 0.01f;
  o.spacing = Vec3d(0.5, 1, 2);
  const Volume v = import_raw(path, {{2, 2, 2}, ScalarType::F32, Endian::Little}, o);
  EXPECT_EQ(v.active_voxel_count(), 3u);  // -0.02, 1.5, 2.0
  EXPECT_EQ(v.voxel_size(), Vec3d(0.5, 1, 2));
  EXPECT_FLOAT_EQ(v.value_at({0, 1, 1}), 2.0f);
}

TEST(ImportRaw, SizeMismatchNamesExpectedAndActualBytes) {
  const std::string path = test::make_temp_dir("raw_size") + "/v.raw";
  write_file(path, std::string(63, '\x01'));
  const std::string msg =
      invalid_input_message([&] { import_raw(path, {{4, 4, 4}, ScalarType::U8, Endian::Little}); });
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected 64 bytes"), std::string::npos) << msg;
  EXPECT_NE(msg.find("got 63 bytes"), std::string::npos) << msg;
  const std::string msg16 =
      invalid_input_message([&] { import_raw(path, {{4, 4, 4}, ScalarType::U16, Endian::Big}); });
  EXPECT_NE(msg16.find("expected 128 bytes"), std::string::npos) << msg16;
}

TEST(ImportRaw, GzipInputIsDecompressed) {
  const std::string dir = test::make_temp_dir("raw_gz");
  std::uint64_t nonzero = 0;
  const std::string bytes = sparse_u8(nonzero);
  write_file(dir + "/v.raw.gz", gzip_stored(bytes));
  const Volume v = import_raw(dir + "/v.raw.gz", {{16, 12, 10}, ScalarType::U8, Endian::Little});
  EXPECT_EQ(v.active_voxel_count(), nonzero);
  EXPECT_EQ(v.value_at({5, 2, 0}), float(static_cast<unsigned char>(bytes[37])));
  const std::string msg = invalid_input_message(
      [&] { import_raw(dir + "/v.raw.gz", {{16, 12, 11}, ScalarType::U8, Endian::Little}); });
  EXPECT_NE(msg.find("got 1920 bytes after gunzip"), std::string::npos) << msg;
  const std::string gz = gzip_stored(bytes);
  write_file(dir + "/cut.raw.gz", gz.substr(0, gz.size() / 2));
  EXPECT_THROW(import_raw(dir + "/cut.raw.gz", {{16, 12, 10}, ScalarType::U8, Endian::Little}), IoError);
}

TEST(ImportRaw, BadDimsAndInputs) {
  const std::string dir = test::make_temp_dir("raw_bad");
  write_file(dir + "/v.raw", std::string(8, '\0'));
  EXPECT_NE(invalid_input_message([&] { import_raw(dir + "/v.raw", {{0, 2, 4}, ScalarType::U8, Endian::Little}); })
                .find("dims must be positive"),
            std::string::npos);
  EXPECT_NE(invalid_input_message([&] {
              import_raw(dir + "/v.raw", {{2000000000, 2000000000, 8}, ScalarType::U8, Endian::Little});
            }).find("overflow"),
            std::string::npos);
  EXPECT_THROW(import_raw(dir + "/missing.raw", {{2, 2, 2}, ScalarType::U8, Endian::Little}), IoError);
  EXPECT_THROW(import_raw(dir, {{2, 2, 2}, ScalarType::U8, Endian::Little}), IoError);
  write_file(dir + "/nan.raw", le_floats({1, 2, std::nanf(""), 4, 5, 6, 7, 8}));
  EXPECT_NE(invalid_input_message([&] { import_raw(dir + "/nan.raw", {{2, 2, 2}, ScalarType::F32, Endian::Little}); })
                .find("voxel (0, 1, 0) is NaN"),
            std::string::npos);
  EXPECT_THROW(scalar_type_from_name("u7"), InvalidInput);
  EXPECT_EQ(scalar_type_from_name("i16"), ScalarType::I16);
}

const std::string kHeaderU16 =
    "NRRD0004\n# a comment\ntype: unsigned short\ndimension: 3\nsizes: 2 2 2\nendian: big\n"
    "spacings: 0.5 0.75 2\nspace origin: (10,20,30)\nkey:=value\n";
const std::vector<std::uint16_t> kValues = {0, 7, 0, 300, 0, 0, 65535, 2};

void expect_u16_volume(const Volume& v) {
  EXPECT_EQ(v.active_voxel_count(), 4u);
  EXPECT_EQ(v.value_at({1, 0, 0}), 7.0f);
  EXPECT_EQ(v.value_at({1, 1, 0}), 300.0f);
  EXPECT_EQ(v.value_at({0, 1, 1}), 65535.0f);
  EXPECT_EQ(v.voxel_size(), Vec3d(0.5, 0.75, 2));
  EXPECT_EQ(v.index_to_world({0, 0, 0}), Vec3d(10, 20, 30));
}

TEST(ImportNrrd, AttachedRawGzipAsciiAndDetachedAgree) {
  const std::string dir = test::make_temp_dir("nrrd_good");
  write_file(dir + "/raw.nrrd", kHeaderU16 + "encoding: raw\n\n" + be16(kValues));
  expect_u16_volume(import_nrrd(dir + "/raw.nrrd"));
  write_file(dir + "/gz.nrrd", kHeaderU16 + "encoding: gzip\n\n" + gzip_stored(be16(kValues)));
  expect_u16_volume(import_nrrd(dir + "/gz.nrrd"));
  write_file(dir + "/txt.nrrd", kHeaderU16 + "encoding: ascii\n\n0 7 0 300\n0 0 65535 2\n");
  expect_u16_volume(import_nrrd(dir + "/txt.nrrd"));
  write_file(dir + "/data.bin", "HEADER\n" + be16(kValues));
  write_file(dir + "/det.nhdr", kHeaderU16 + "encoding: raw\nline skip: 1\ndata file: data.bin\n");
  expect_u16_volume(import_nrrd(dir + "/det.nhdr"));
  EXPECT_TRUE(is_nrrd_path(dir + "/det.NHDR"));
}

// Rotated, mirrored (det = -1) directions and an origin, checked against world = o + i*d0 + j*d1 + k*d2
// written out by hand: d0 = (0,0.3,0.4), d1 = (2,0,0), d2 = (0,-0.8,0.6), o = (10,-5,3).
TEST(ImportNrrd, SpaceDirectionsAndOriginBecomeTheAffineTransform) {
  const std::string dir = test::make_temp_dir("nrrd_dirs");
  std::string data;
  for (int v = 1; v <= 12; ++v) data.push_back(char(v));  // 2x3x2 voxels, all active
  write_file(dir + "/d.nrrd",
             "NRRD0005\ntype: uint8\ndimension: 3\nsizes: 2 3 2\nspace: right-anterior-superior\n"
             "space directions: (0,0.3,0.4) (2,0,0) (0,-0.8,0.6)\nspace origin: (10,-5,3)\nencoding: raw\n\n" +
                 data);
  const Volume v = import_nrrd(dir + "/d.nrrd");
  struct Case {
    Vec3d index, world;
  };
  const Case cases[] = {{{0, 0, 0}, {10, -5, 3}},       {{1, 0, 0}, {10, -4.7, 3.4}},
                        {{0, 1, 0}, {12, -5, 3}},       {{0, 0, 1}, {10, -5.8, 3.6}},
                        {{1, 2, 1}, {14, -5.5, 4.0}},   {{0.5, 1.5, 0.5}, {13, -5.25, 3.5}}};
  for (const Case& c : cases) {
    const Vec3d w = v.index_to_world(c.index), i = v.world_to_index(c.world);
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(w[a], c.world[a], 1e-12) << "index " << c.index << " axis " << a;
      EXPECT_NEAR(i[a], c.index[a], 1e-12) << "world " << c.world << " axis " << a;
    }
  }
  EXPECT_NEAR(v.voxel_size().x, 0.5, 1e-12);
  EXPECT_NEAR(v.voxel_size().y, 2.0, 1e-12);
  EXPECT_NEAR(v.voxel_size().z, 1.0, 1e-12);
  // World bbox of the active voxel centres: the extremes of the 8 corners i in {0,1}, j in {0,2}, k in {0,1}.
  const GridInfo info = v.info();
  const Vec3d lo{10, -5.8, 3}, hi{14, -4.7, 4};
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(info.bbox_min[a], lo[a], 1e-12);
    EXPECT_NEAR(info.bbox_max[a], hi[a], 1e-12);
  }
  ImportOptions o;  // --spacing keeps the directions, replaces their lengths
  o.spacing = Vec3d(1, 1, 1);
  const Vec3d w = import_nrrd(dir + "/d.nrrd", o).index_to_world({1, 1, 1});
  const Vec3d expect{10 + 1.0, -5 + 0.6 - 0.8, 3 + 0.8 + 0.6};
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(w[a], expect[a], 1e-12);
}

TEST(ImportNrrd, DependentSpaceDirectionsAreRejected) {
  const std::string dir = test::make_temp_dir("nrrd_dep");
  write_file(dir + "/d.nrrd",
             "NRRD0005\ntype: uint8\ndimension: 3\nsizes: 1 1 1\n"
             "space directions: (1,0,0) (2,0,0) (0,0,1)\nencoding: raw\n\n" + std::string("\x05", 1));
  EXPECT_THROW(import_nrrd(dir + "/d.nrrd"), InvalidInput);
}

TEST(ImportNrrd, MalformedHeadersNameTheLine) {
  const std::string dir = test::make_temp_dir("nrrd_bad");
  const std::string data = be16(kValues);
  struct Case {
    std::string text, expect;
  };
  const std::vector<Case> cases = {
      {"P6\n", ":1: not a NRRD file"},
      {"NRRD0004\ntype: float\nthis line has no colon\n\n", ":3: expected 'field: value'"},
      {"NRRD0004\ntype: float\ndimension: 2\n\n", ":3: raysift imports 3-D volumes"},
      {"NRRD0004\ntype: complex\n\n", ":2: type 'complex' is not supported"},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2\nencoding: raw\n\n", "'sizes' has 2 entries"},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 0 2\n\n", ":4: sizes must be positive"},
      {"NRRD0004\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n", ":5: the header has no 'type' field"},
      {"NRRD0004\ntype: ushort\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n", "needs an 'endian' field"},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: bzip2\n\n", ":5: encoding 'bzip2'"},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nspacings: 1 x 1\n", ":5: spacings must be a finite"},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2000000000 2000000000 8\nencoding: raw\n\n", "overflow"},
      {"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n1234567", "expected 8 bytes"},
  };
  for (std::size_t c = 0; c < cases.size(); ++c) {
    const std::string path = dir + "/bad" + std::to_string(c) + ".nrrd";
    write_file(path, cases[c].text);
    const std::string msg = invalid_input_message([&] { import_nrrd(path); });
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find(cases[c].expect), std::string::npos) << "case " << c << ": " << msg;
  }
  write_file(dir + "/nodata.nhdr", kHeaderU16 + "encoding: raw\ndata file: missing.raw\n");
  EXPECT_THROW(import_nrrd(dir + "/nodata.nhdr"), IoError);
}

}  // namespace
}  // namespace raysift::volume
