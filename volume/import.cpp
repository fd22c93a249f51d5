#include "volume/import.h"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>
#include <vector>

#include "core/errors.h"
#include "core/file_util.h"

namespace raysift::volume {

namespace {

struct TypeName {
  ScalarType type;
  const char* name;
  int bytes;
};
constexpr TypeName kTypes[] = {{ScalarType::U8, "u8", 1},   {ScalarType::I8, "i8", 1},   {ScalarType::U16, "u16", 2},
                               {ScalarType::I16, "i16", 2}, {ScalarType::U32, "u32", 4}, {ScalarType::I32, "i32", 4},
                               {ScalarType::F32, "f32", 4}, {ScalarType::F64, "f64", 8}};

const TypeName& type_entry(ScalarType t) {
  for (const TypeName& e : kTypes)
    if (e.type == t) return e;
  RAYSIFT_CHECK(false);
}

bool host_is_little_endian() {
  const std::uint16_t one = 1;
  unsigned char first;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

std::string dims_text(const Vec3i& d) {
  return std::to_string(d.x) + "x" + std::to_string(d.y) + "x" + std::to_string(d.z);
}

/// Bytes of a dense dims volume of `type`. \throw InvalidInput for non-positive dims or 64-bit overflow.
std::uint64_t dense_bytes(const std::string& path, const Vec3i& dims, ScalarType type) {
  if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0)
    throw InvalidInput(file_message(path, "dims must be positive on every axis, got " + dims_text(dims)));
  std::uint64_t n = std::uint64_t(dims.x), out = 0;
  if (__builtin_mul_overflow(n, std::uint64_t(dims.y), &n) || __builtin_mul_overflow(n, std::uint64_t(dims.z), &n) ||
      __builtin_mul_overflow(n, std::uint64_t(type_entry(type).bytes), &out))
    throw InvalidInput(file_message(path, "dims " + dims_text(dims) + " of " + type_entry(type).name +
                                              " voxels overflow a 64-bit byte count; check the dims"));
  return out;
}

/// Decompressed gzip (or zlib) data, keeping at most `keep` bytes but counting all of them, so a size mismatch
/// can be reported exactly without holding an oversized (or malicious) stream in memory.
struct Inflated {
  std::string bytes;
  std::uint64_t total = 0;
};

Inflated gunzip(const std::string& path, const char* data, std::size_t size, std::uint64_t keep) {
  z_stream zs{};
  if (inflateInit2(&zs, 15 + 32) != Z_OK)  // 15 + 32: accept gzip or zlib headers
    throw IoError(file_message(path, "cannot initialise zlib"));
  Inflated out;
  std::vector<unsigned char> chunk(1 << 20);
  zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data));
  zs.avail_in = 0;
  std::size_t fed = 0;
  int rc = Z_OK;
  for (;;) {
    if (zs.avail_in == 0 && fed < size) {
      const std::size_t n = std::min<std::size_t>(size - fed, 1u << 30);
      zs.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data + fed));
      zs.avail_in = uInt(n);
      fed += n;
    }
    zs.next_out = chunk.data();
    zs.avail_out = uInt(chunk.size());
    rc = inflate(&zs, Z_NO_FLUSH);
    const std::size_t produced = chunk.size() - zs.avail_out;
    if (out.bytes.size() < keep)
      out.bytes.append(reinterpret_cast<const char*>(chunk.data()),
                       std::min<std::uint64_t>(produced, keep - out.bytes.size()));
    out.total += produced;
    if (rc == Z_STREAM_END) {
      if (zs.avail_in == 0 && fed == size) break;
      inflateReset(&zs);  // concatenated gzip members
      continue;
    }
    if (rc == Z_BUF_ERROR && zs.avail_in == 0 && fed == size) {
      inflateEnd(&zs);
      throw IoError(file_message(path, "gzip data is truncated (ends after " + std::to_string(out.total) +
                                           " decompressed bytes)"));
    }
    if (rc != Z_OK && rc != Z_BUF_ERROR) {
      const std::string msg = zs.msg ? zs.msg : "error " + std::to_string(rc);
      inflateEnd(&zs);
      throw IoError(file_message(path, "corrupt gzip data (" + msg + ")"));
    }
  }
  inflateEnd(&zs);
  return out;
}

struct Geometry {
  Vec3i dims;
  Vec3d spacing{1, 1, 1};
  Vec3d origin{0, 0, 0};
  std::optional<std::array<Vec3d, 3>> axes;  ///< NRRD space directions: world step of each index axis
};

void validate_options(const std::string& path, const ImportOptions& o) {
  if (o.spacing && !(o.spacing->x > 0 && o.spacing->y > 0 && o.spacing->z > 0 && is_finite(*o.spacing)))
    throw InvalidInput(file_message(path, "spacing must be positive and finite on every axis"));
  if (!(o.tolerance >= 0) || !std::isfinite(o.tolerance) || !std::isfinite(o.background))
    throw InvalidInput(file_message(path, "background must be finite and tolerance >= 0"));
}

float decode(const unsigned char* p, ScalarType t, bool swap) {
  unsigned char b[8];
  const int n = type_entry(t).bytes;
  if (swap)
    for (int i = 0; i < n; ++i) b[i] = p[n - 1 - i];
  else
    std::memcpy(b, p, std::size_t(n));
  switch (t) {
    case ScalarType::U8: return float(b[0]);
    case ScalarType::I8: return float(std::int8_t(b[0]));
    case ScalarType::U16: { std::uint16_t v; std::memcpy(&v, b, 2); return float(v); }
    case ScalarType::I16: { std::int16_t v; std::memcpy(&v, b, 2); return float(v); }
    case ScalarType::U32: { std::uint32_t v; std::memcpy(&v, b, 4); return float(v); }
    case ScalarType::I32: { std::int32_t v; std::memcpy(&v, b, 4); return float(v); }
    case ScalarType::F32: { float v; std::memcpy(&v, b, 4); return v; }
    case ScalarType::F64: { double v; std::memcpy(&v, b, 8); return float(v); }
  }
  return 0.0f;
}

/// Builds the sparse volume from exactly dense_bytes(dims, type) bytes at `data`.
Volume build_volume(const std::string& path, const unsigned char* data, ScalarType type, Endian endian,
                    const Geometry& geo, const ImportOptions& options) {
  const bool swap = type_entry(type).bytes > 1 && (endian == Endian::Little) != host_is_little_endian();
  const std::size_t stride = std::size_t(type_entry(type).bytes);
  const std::size_t nx = std::size_t(geo.dims.x), nxy = nx * std::size_t(geo.dims.y);
  if (type == ScalarType::F32 || type == ScalarType::F64) {
    // Stage boundary check (STYLE.md §6): a NaN/Inf voxel would poison every ray through it.
    const std::size_t count = nxy * std::size_t(geo.dims.z);
    for (std::size_t i = 0; i < count; ++i)
      if (!std::isfinite(decode(data + i * stride, type, swap))) {
        std::ostringstream s;
        s << "voxel (" << i % nx << ", " << (i / nx) % std::size_t(geo.dims.y) << ", " << i / nxy
          << ") is NaN/Inf (or out of float range); fix the data before import";
        throw InvalidInput(file_message(path, s.str()));
      }
  }
  DenseSpec spec;
  spec.dims = geo.dims;
  spec.voxel_size = options.spacing ? *options.spacing : geo.spacing;
  spec.origin_ws = geo.origin;
  if (geo.axes) {
    spec.axes_ws = geo.axes;
    // --spacing keeps the NRRD's directions and replaces their lengths.
    if (options.spacing)
      for (int a = 0; a < 3; ++a)
        (*spec.axes_ws)[std::size_t(a)] = normalize((*geo.axes)[std::size_t(a)]) * (*options.spacing)[a];
  }
  spec.background = options.background;
  spec.tolerance = options.tolerance;
  return Volume::from_function(
      spec,
      [&](int i, int j, int k) {
        return decode(data + (std::size_t(i) + nx * std::size_t(j) + nxy * std::size_t(k)) * stride, type, swap);
      },
      options.grid_name);
}

/// Memory of the import: the dense data (`dense` bytes, plus `extra` already held, e.g. compressed input) and
/// the grid it becomes when every voxel is active.
void check_import_memory(const std::string& path, const ImportOptions& options, std::uint64_t dense,
                         ScalarType type, std::uint64_t extra) {
  if (!options.memory_limit) return;
  const std::uint64_t voxels = dense / std::uint64_t(type_entry(type).bytes);
  require_memory(saturating_product(1, dense + extra) + grid_bytes_upper_bound(voxels), *options.memory_limit,
                 SizeSource::Input, file_message(path, "importing " + std::to_string(voxels) + " voxels"));
}

[[noreturn]] void size_mismatch(const std::string& path, std::uint64_t expected, std::uint64_t actual,
                                const Vec3i& dims, ScalarType type, const std::string& what) {
  throw InvalidInput(file_message(path, "expected " + std::to_string(expected) + " bytes (" + dims_text(dims) + " " +
                                            type_entry(type).name + "), got " + std::to_string(actual) + " bytes" +
                                            what + "; check the dims and voxel type"));
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

ScalarType scalar_type_from_name(const std::string& name) {
  std::string valid;
  for (const TypeName& e : kTypes) {
    if (name == e.name) return e.type;
    valid += std::string(valid.empty() ? "" : ", ") + e.name;
  }
  throw InvalidInput("unknown voxel type '" + name + "'; must be one of: " + valid);
}

std::string scalar_type_name(ScalarType type) { return type_entry(type).name; }
int scalar_type_bytes(ScalarType type) { return type_entry(type).bytes; }

bool is_nrrd_path(const std::string& path) {
  const std::string ext = file_extension(path);
  return ext == ".nrrd" || ext == ".nhdr";
}

Volume import_raw(const std::string& path, const RawLayout& layout, const ImportOptions& options) {
  validate_options(path, options);
  require_readable_file(path);
  const std::uint64_t expected = dense_bytes(path, layout.dims, layout.type);
  Geometry geo;
  geo.dims = layout.dims;
  if (ends_with(lower(path), ".gz")) {
    std::error_code size_ec;
    check_import_memory(path, options, expected, layout.type, std::filesystem::file_size(path, size_ec));
    const std::string packed = read_file_bytes(path);
    const Inflated raw = gunzip(path, packed.data(), packed.size(), expected);
    if (raw.total != expected) size_mismatch(path, expected, raw.total, layout.dims, layout.type, " after gunzip");
    return build_volume(path, reinterpret_cast<const unsigned char*>(raw.bytes.data()), layout.type, layout.endian,
                        geo, options);
  }
  // Check the size before reading, so absurd dims never allocate.
  std::error_code ec;
  const std::uint64_t actual = std::filesystem::file_size(path, ec);
  if (ec) throw IoError(file_message(path, "cannot get file size: " + ec.message()));
  if (actual != expected) size_mismatch(path, expected, actual, layout.dims, layout.type, "");
  check_import_memory(path, options, expected, layout.type, 0);
  const std::string raw = read_file_bytes(path);
  return build_volume(path, reinterpret_cast<const unsigned char*>(raw.data()), layout.type, layout.endian, geo,
                      options);
}

namespace {

/// The header fields raysift uses, as parsed from a NRRD header.
struct NrrdHeader {
  int dimension = 0;
  std::vector<long long> sizes;
  std::optional<ScalarType> type;
  std::optional<Endian> endian;
  std::string encoding;
  std::optional<Vec3d> spacings, origin;
  std::vector<Vec3d> directions;
  std::string data_file;
  long long byte_skip = 0, line_skip = 0;
  std::size_t data_offset = 0;  ///< start of attached data in the header file
  int end_line = 0;
};

class NrrdParser {
 public:
  NrrdParser(const std::string& path, const std::string& text) : path_(path), text_(text) {}

  NrrdHeader parse() {
    std::string line;
    if (!next_line(line) || line.rfind("NRRD000", 0) != 0 || line.size() != 8)
      fail("not a NRRD file: the first line must be NRRD0001..NRRD0005, got '" + line.substr(0, 40) + "'");
    bool has_blank = false;
    while (next_line(line)) {
      if (line.empty()) {
        has_blank = true;
        break;
      }
      if (line[0] == '#' || line.find(":=") != std::string::npos) continue;  // comment, key/value pair
      const auto colon = line.find(": ");
      if (colon == std::string::npos) fail("expected 'field: value', got '" + line.substr(0, 60) + "'");
      field(lower(trim(line.substr(0, colon))), trim(line.substr(colon + 2)));
    }
    h_.data_offset = has_blank ? pos_ : text_.size();
    h_.end_line = line_no_;
    require(!h_.type.has_value(), "type");
    require(h_.dimension == 0, "dimension");
    require(h_.sizes.empty(), "sizes");
    require(h_.encoding.empty(), "encoding");
    if (int(h_.sizes.size()) != h_.dimension)
      fail("'sizes' has " + std::to_string(h_.sizes.size()) + " entries but dimension is " +
           std::to_string(h_.dimension));
    if (scalar_type_bytes(*h_.type) > 1 && h_.encoding != "ascii" && !h_.endian)
      fail("the header needs an 'endian' field for multi-byte voxels");
    if (!has_blank && h_.data_file.empty()) fail("no blank line ends the header and there is no 'data file'");
    return h_;
  }

 private:
  bool next_line(std::string& line) {
    if (pos_ >= text_.size()) return false;
    const auto nl = text_.find('\n', pos_);
    const std::size_t end = nl == std::string::npos ? text_.size() : nl;
    line = text_.substr(pos_, end - pos_);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos_ = nl == std::string::npos ? text_.size() : nl + 1;
    ++line_no_;
    return true;
  }

  [[noreturn]] void fail(const std::string& msg) const {
    throw InvalidInput(path_ + ":" + std::to_string(line_no_) + ": " + msg);
  }

  void require(bool missing, const char* name) const {
    if (missing) fail(std::string("the header has no '") + name + "' field");
  }

  long long integer(const std::string& s, const char* what) const {
    std::size_t used = 0;
    long long v = 0;
    try {
      v = std::stoll(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size()) fail(std::string(what) + " must be an integer, got '" + s + "'");
    return v;
  }

  double number(const std::string& s, const char* what) const {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size() || !std::isfinite(v)) fail(std::string(what) + " must be a finite number, got '" + s + "'");
    return v;
  }

  std::vector<std::string> words(const std::string& s) const {
    std::istringstream in(s);
    std::vector<std::string> out;
    for (std::string w; in >> w;) out.push_back(w);
    return out;
  }

  /// "(x,y,z)" -> vector. \throw InvalidInput for any other form.
  Vec3d vector(const std::string& s, const char* what) const {
    if (s.size() < 2 || s.front() != '(' || s.back() != ')')
      fail(std::string(what) + " must be a vector like (1,0,0), got '" + s + "'");
    std::vector<std::string> parts;
    std::stringstream in(s.substr(1, s.size() - 2));
    for (std::string p; std::getline(in, p, ',');) parts.push_back(trim(p));
    if (parts.size() != 3) fail(std::string(what) + " must have 3 components, got '" + s + "'");
    return {number(parts[0], what), number(parts[1], what), number(parts[2], what)};
  }

  void field(const std::string& name, const std::string& value) {
    if (name == "dimension") {
      h_.dimension = int(integer(value, "dimension"));
      if (h_.dimension != 3) fail("raysift imports 3-D volumes, got dimension " + value);
    } else if (name == "type") {
      h_.type = nrrd_type(lower(value));
    } else if (name == "sizes") {
      for (const std::string& w : words(value)) {
        const long long n = integer(w, "sizes");
        if (n <= 0) fail("sizes must be positive, got '" + value + "'");
        if (n > std::numeric_limits<int>::max()) fail("size " + w + " exceeds the 2^31-1 index range of a VDB grid");
        h_.sizes.push_back(n);
      }
    } else if (name == "endian") {
      const std::string v = lower(value);
      if (v != "little" && v != "big") fail("endian must be 'little' or 'big', got '" + value + "'");
      h_.endian = v == "little" ? Endian::Little : Endian::Big;
    } else if (name == "encoding") {
      const std::string v = lower(value);
      if (v == "raw") h_.encoding = "raw";
      else if (v == "gzip" || v == "gz") h_.encoding = "gzip";
      else if (v == "ascii" || v == "text" || v == "txt") h_.encoding = "ascii";
      else fail("encoding '" + value + "' is not supported; use raw, gzip or ascii");
    } else if (name == "spacings") {
      const auto w = words(value);
      if (w.size() != 3) fail("spacings needs 3 values, got '" + value + "'");
      h_.spacings = Vec3d(number(w[0], "spacings"), number(w[1], "spacings"), number(w[2], "spacings"));
      if (!(h_.spacings->x > 0 && h_.spacings->y > 0 && h_.spacings->z > 0))
        fail("spacings must be positive, got '" + value + "'");
    } else if (name == "space directions") {
      h_.directions.clear();
      for (const std::string& w : words(value)) h_.directions.push_back(vector(w, "space directions"));
      if (h_.directions.size() != 3) fail("space directions needs 3 vectors, got '" + value + "'");
      for (const Vec3d& d : h_.directions)
        if (!(length(d) > 0)) fail("space directions must be non-zero vectors, got '" + value + "'");
      const std::vector<Vec3d>& d = h_.directions;
      // Relative to the lengths, so tiny (micrometre) and huge voxels are judged alike.
      if (!(std::abs(dot(d[0], cross(d[1], d[2]))) > 1e-9 * length(d[0]) * length(d[1]) * length(d[2])))
        fail("space directions must be linearly independent, got '" + value + "'");
    } else if (name == "space origin") {
      h_.origin = vector(value, "space origin");
    } else if (name == "data file" || name == "datafile") {
      if (value.rfind("LIST", 0) == 0 || words(value).size() != 1)
        fail("multi-file 'data file' forms are not supported; give one file");
      h_.data_file = value;
    } else if (name == "byte skip" || name == "byteskip") {
      h_.byte_skip = integer(value, "byte skip");
      if (h_.byte_skip < -1) fail("byte skip must be >= -1, got " + value);
    } else if (name == "line skip" || name == "lineskip") {
      h_.line_skip = integer(value, "line skip");
      if (h_.line_skip < 0) fail("line skip must be >= 0, got " + value);
    }
    // Other fields (space, kinds, centers, units, content, ...) do not affect the voxel values or spacing.
  }

  ScalarType nrrd_type(const std::string& t) const {
    static const std::pair<const char*, ScalarType> names[] = {
        {"signed char", ScalarType::I8},    {"int8", ScalarType::I8},
        {"int8_t", ScalarType::I8},         {"uchar", ScalarType::U8},
        {"unsigned char", ScalarType::U8},  {"uint8", ScalarType::U8},
        {"uint8_t", ScalarType::U8},        {"short", ScalarType::I16},
        {"short int", ScalarType::I16},     {"signed short", ScalarType::I16},
        {"signed short int", ScalarType::I16}, {"int16", ScalarType::I16},
        {"int16_t", ScalarType::I16},       {"ushort", ScalarType::U16},
        {"unsigned short", ScalarType::U16}, {"unsigned short int", ScalarType::U16},
        {"uint16", ScalarType::U16},        {"uint16_t", ScalarType::U16},
        {"int", ScalarType::I32},           {"signed int", ScalarType::I32},
        {"int32", ScalarType::I32},         {"int32_t", ScalarType::I32},
        {"uint", ScalarType::U32},          {"unsigned int", ScalarType::U32},
        {"uint32", ScalarType::U32},        {"uint32_t", ScalarType::U32},
        {"float", ScalarType::F32},         {"double", ScalarType::F64}};
    for (const auto& [name, type] : names)
      if (t == name) return type;
    fail("type '" + t + "' is not supported; use an 8/16/32-bit integer, float or double type");
  }

  const std::string& path_;
  const std::string& text_;
  std::size_t pos_ = 0;
  int line_no_ = 0;
  NrrdHeader h_;
};

/// Skips `lines` newline-terminated lines from `offset`. \throw InvalidInput if the data ends first.
std::size_t skip_lines(const std::string& path, const std::string& data, std::size_t offset, long long lines) {
  for (long long i = 0; i < lines; ++i) {
    const auto nl = data.find('\n', offset);
    if (nl == std::string::npos)
      throw InvalidInput(file_message(path, "line skip " + std::to_string(lines) + " runs past the end of the data"));
    offset = nl + 1;
  }
  return offset;
}

/// ASCII samples as host-order doubles. \throw InvalidInput on a non-number or a count mismatch.
std::string parse_ascii(const std::string& path, const char* begin, const char* end, std::uint64_t count) {
  std::string out;
  out.reserve(std::size_t(count) * 8);
  std::uint64_t n = 0;
  std::string token;
  for (const char* p = begin;; ++p) {
    const bool sep = p == end || std::isspace(static_cast<unsigned char>(*p)) || *p == ',';
    if (!sep) {
      token.push_back(*p);
      continue;
    }
    if (!token.empty()) {
      char* used = nullptr;
      const double v = std::strtod(token.c_str(), &used);
      if (*used != '\0')
        throw InvalidInput(file_message(path, "ascii data: '" + token + "' is not a number (sample " +
                                                  std::to_string(n) + ")"));
      if (n < count) out.append(reinterpret_cast<const char*>(&v), 8);
      ++n;
      token.clear();
    }
    if (p == end) break;
  }
  if (n != count)
    throw InvalidInput(file_message(path, "ascii data: expected " + std::to_string(count) + " samples, got " +
                                              std::to_string(n)));
  return out;
}

}  // namespace

Volume import_nrrd(const std::string& path, const ImportOptions& options) {
  validate_options(path, options);
  const std::string text = read_file_bytes(path);
  const NrrdHeader h = NrrdParser(path, text).parse();
  Geometry geo;
  geo.dims = {int(h.sizes[0]), int(h.sizes[1]), int(h.sizes[2])};
  if (h.spacings) {
    geo.spacing = *h.spacings;
  } else if (!h.directions.empty()) {
    // World = space origin + directions * index in the NRRD's own space (no RAS/LPS conversion).
    geo.spacing = {length(h.directions[0]), length(h.directions[1]), length(h.directions[2])};
    geo.axes = std::array<Vec3d, 3>{h.directions[0], h.directions[1], h.directions[2]};
  }
  if (h.origin) geo.origin = *h.origin;
  const ScalarType type = *h.type;
  const std::uint64_t expected = dense_bytes(path, geo.dims, type);
  // ascii data is parsed into doubles (8 bytes per voxel) before the grid is built.
  check_import_memory(path, options, h.encoding == "ascii" ? expected / std::uint64_t(scalar_type_bytes(type)) * 8
                                                           : expected,
                      h.encoding == "ascii" ? ScalarType::F64 : type, text.size());

  std::string detached;
  std::string data_path = path;
  if (!h.data_file.empty()) {
    const std::filesystem::path p(h.data_file);
    data_path = p.is_absolute() ? p.string() : (std::filesystem::path(path).parent_path() / p).string();
    detached = read_file_bytes(data_path);
  }
  const std::string& blob = h.data_file.empty() ? text : detached;
  std::size_t offset = skip_lines(data_path, blob, h.data_file.empty() ? h.data_offset : 0, h.line_skip);

  if (h.encoding == "ascii") {
    const std::uint64_t count = expected / std::uint64_t(scalar_type_bytes(type));
    const std::string values = parse_ascii(data_path, blob.data() + offset, blob.data() + blob.size(), count);
    return build_volume(data_path, reinterpret_cast<const unsigned char*>(values.data()), ScalarType::F64,
                        host_is_little_endian() ? Endian::Little : Endian::Big, geo, options);  // host order
  }
  const Endian endian = h.endian.value_or(Endian::Little);
  if (h.encoding == "gzip") {
    if (h.byte_skip < 0) throw InvalidInput(file_message(path, "byte skip -1 is only valid with raw encoding"));
    const std::uint64_t skip = std::uint64_t(h.byte_skip);
    const Inflated raw = gunzip(data_path, blob.data() + offset, blob.size() - offset, expected + skip);
    if (raw.total < skip || raw.total - skip != expected)
      size_mismatch(data_path, expected, raw.total < skip ? 0 : raw.total - skip, geo.dims, type,
                    " after gunzip and byte skip");
    return build_volume(data_path, reinterpret_cast<const unsigned char*>(raw.bytes.data()) + skip, type, endian,
                        geo, options);
  }
  const std::uint64_t available = blob.size() - offset;
  if (h.byte_skip == -1) {
    if (available < expected) size_mismatch(data_path, expected, available, geo.dims, type, "");
    offset = blob.size() - std::size_t(expected);  // -1: the data is the last `expected` bytes
  } else if (std::uint64_t(h.byte_skip) > available || available - std::uint64_t(h.byte_skip) != expected) {
    size_mismatch(data_path, expected,
                  std::uint64_t(h.byte_skip) > available ? 0 : available - std::uint64_t(h.byte_skip), geo.dims,
                  type, h.byte_skip ? " after byte skip" : "");
  } else {
    offset += std::size_t(h.byte_skip);
  }
  return build_volume(data_path, reinterpret_cast<const unsigned char*>(blob.data()) + offset, type, endian, geo,
                      options);
}

}  // namespace raysift::volume
