#include "mesh/detail/ply_reader.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <string_view>
#include <vector>

#include "core/errors.h"
#include "mesh/detail/polygon_fan.h"

namespace raysift::mesh::detail {
namespace {

struct PlyType {
  const char* name;
  const char* alias;
  int bytes;
  bool integral;
  bool is_signed;
};

constexpr PlyType kTypes[] = {{"char", "int8", 1, true, true},      {"uchar", "uint8", 1, true, false},
                              {"short", "int16", 2, true, true},    {"ushort", "uint16", 2, true, false},
                              {"int", "int32", 4, true, true},      {"uint", "uint32", 4, true, false},
                              {"float", "float32", 4, false, true}, {"double", "float64", 8, false, true}};

const PlyType* find_type(const std::string& name) {
  for (const PlyType& t : kTypes)
    if (name == t.name || name == t.alias) return &t;
  return nullptr;
}

struct PlyProperty {
  std::string name;
  const PlyType* type = nullptr;        // the value type; for a list, the type of its items
  const PlyType* count_type = nullptr;  // non-null for a list
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { ascii, binary_little_endian, binary_big_endian };

struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;
  int body_first_line = 0;
};

[[noreturn]] void fail(const std::string& path, int line, const std::string& message) {
  throw IoError(path + ":" + std::to_string(line) + ": " + message);
}

/// Adds one header line to `header`; the grammar is PLY 1.0's, and anything else is an error (OpenMesh read past
/// malformed lines into crashes and endless loops).
void parse_header_line(const std::string& path, int number, const std::string& line, bool& seen_format,
                       PlyHeader& header, std::set<std::string>& element_names) {
  const auto malformed = [&] { fail(path, number, "malformed PLY header line '" + line.substr(0, 60) + "'"); };
  std::istringstream in(line);
  std::string word, a, b, c, rest;
  if (!(in >> word)) malformed();
  if (word == "comment" || word == "obj_info") return;
  if (word == "format") {
    if (seen_format || !(in >> a >> b) || (in >> rest) || b != "1.0") malformed();  // PLY has one version
    if (a == "ascii") header.format = PlyFormat::ascii;
    else if (a == "binary_little_endian") header.format = PlyFormat::binary_little_endian;
    else if (a == "binary_big_endian") header.format = PlyFormat::binary_big_endian;
    else malformed();
    seen_format = true;
    return;
  }
  if (word == "element") {
    long long count = -1;
    if (!(in >> a >> count) || count < 0 || (in >> rest)) malformed();
    if (!element_names.insert(a).second) fail(path, number, "PLY element '" + a + "' declared twice");
    header.elements.push_back({a, std::uint64_t(count), {}});
    return;
  }
  if (word != "property" || header.elements.empty() || !(in >> a >> b)) malformed();
  PlyProperty property;
  if (a == "list") {
    property.count_type = find_type(b);
    if (!property.count_type || !property.count_type->integral || !(in >> c >> property.name)) malformed();
    property.type = find_type(c);
  } else {
    property.type = find_type(a);
    property.name = b;
  }
  if (!property.type || (in >> rest)) malformed();
  header.elements.back().properties.push_back(property);
}

PlyHeader parse_header(const std::string& path, const std::string& data) {
  PlyHeader header;
  bool seen_format = false;
  std::set<std::string> element_names;
  std::size_t start = 0;
  for (int number = 1; start < data.size(); ++number) {
    std::size_t end = data.find('\n', start);
    if (end == std::string::npos) end = data.size();
    std::string line = data.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    start = end + 1;
    if (number == 1) {
      if (line != "ply") fail(path, number, "not a PLY file: the first line is not 'ply'");
    } else if (line == "end_header") {
      if (!seen_format) throw IoError(file_message(path, "malformed PLY: the header has no 'format' line"));
      header.body_offset = std::min(start, data.size());
      header.body_first_line = number + 1;
      return header;
    } else {
      parse_header_line(path, number, line, seen_format, header, element_names);
    }
  }
  throw IoError(file_message(path, "malformed PLY: the header has no 'end_header' line"));
}

/// The values of a PLY body in file order, ASCII tokens or binary words alike. `element`/`index` name the element
/// being read, for the error messages.
class PlyBody {
 public:
  PlyBody(const std::string& path, const std::string& data, const PlyHeader& header)
      : path_(path), data_(data), pos_(header.body_offset), line_(header.body_first_line),
        format_(header.format),
        swap_bytes_((header.format == PlyFormat::binary_big_endian) != host_is_big_endian()) {}

  bool ascii() const { return format_ == PlyFormat::ascii; }
  const std::string& path() const { return path_; }
  std::uint64_t index() const { return index_; }
  std::size_t bytes_left() const { return data_.size() - pos_; }

  /// True when `count` items of at least `min_bytes` each can still fit in the file, so that allocating for them
  /// costs at most the file's own size. An ASCII value takes a digit and a separator.
  bool can_hold(std::uint64_t count, std::uint64_t min_binary_bytes, std::uint64_t values_each) const {
    const std::uint64_t each = ascii() ? 2 * values_each : min_binary_bytes;
    return each == 0 || count <= (bytes_left() + 1) / each;
  }

  void locate(const std::string& element, std::uint64_t index) {
    element_ = &element;
    index_ = index;
  }

  [[noreturn]] void fail(const std::string& message) const {
    const std::string where = *element_ + " " + std::to_string(index_) + ": " + message;
    if (ascii()) raysift::mesh::detail::fail(path_, line_, where);
    throw IoError(file_message(path_, where));
  }

  double value(const PlyType& type) { return ascii() ? ascii_value(type) : binary_value(type); }

 private:
  double ascii_value(const PlyType& type) {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_])))
      if (data_[pos_++] == '\n') ++line_;
    const std::size_t begin = pos_;
    while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    if (begin == pos_) fail("the file ends inside it (truncated PLY)");
    const char* first = data_.data() + begin;
    const char* last = data_.data() + pos_;
    // A float property parses as float: decimal -> double -> float could round twice.
    const bool is_float = !type.integral && type.bytes == 4;
    float f = 0;
    double v = 0;
    const auto [stop, error] = is_float ? std::from_chars(first, last, f) : std::from_chars(first, last, v);
    if (is_float) v = f;
    if (error != std::errc() || stop != last || (type.integral && !in_range(v, type)))
      fail("'" + std::string(first, std::min<std::size_t>(last - first, 40)) + "' is not a valid " + type.name);
    return v;
  }

  double binary_value(const PlyType& type) {
    if (bytes_left() < std::size_t(type.bytes)) fail("the file ends inside it (truncated PLY)");
    unsigned char b[8];
    std::memcpy(b, data_.data() + pos_, type.bytes);
    pos_ += type.bytes;
    if (swap_bytes_) std::reverse(b, b + type.bytes);
    if (!type.integral) return type.bytes == 4 ? double(load<float>(b)) : load<double>(b);
    switch (type.bytes) {
      case 1: return type.is_signed ? double(std::int8_t(b[0])) : double(b[0]);
      case 2: return type.is_signed ? double(load<std::int16_t>(b)) : double(load<std::uint16_t>(b));
      default: return type.is_signed ? double(load<std::int32_t>(b)) : double(load<std::uint32_t>(b));
    }
  }

  static bool in_range(double v, const PlyType& type) {
    const double span = std::ldexp(1.0, 8 * type.bytes);
    const double lo = type.is_signed ? -span / 2 : 0, hi = type.is_signed ? span / 2 - 1 : span - 1;
    return v == std::floor(v) && v >= lo && v <= hi;
  }

  template <class T>
  static T load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof v);
    return v;
  }

  static bool host_is_big_endian() {
    const std::uint16_t one = 1;
    unsigned char first;
    std::memcpy(&first, &one, 1);
    return first == 0;
  }

  const std::string& path_;
  const std::string& data_;
  std::size_t pos_;
  int line_;
  PlyFormat format_;
  bool swap_bytes_;  ///< the file's byte order is not the host's
  const std::string* element_ = nullptr;
  std::uint64_t index_ = 0;
};

/// Reads one list's count, bounded by what the rest of the file can hold.
std::uint64_t list_count(PlyBody& body, const PlyProperty& list) {
  const double n = body.value(*list.count_type);
  if (n < 0) body.fail("list '" + list.name + "' has a negative length " + std::to_string(std::int64_t(n)));
  if (!body.can_hold(std::uint64_t(n), list.type->bytes, 1))
    body.fail("list '" + list.name + "' of " + std::to_string(std::uint64_t(n)) + " items is longer than the file");
  return std::uint64_t(n);
}

void require_element_fits(const PlyBody& body, const PlyElement& element) {
  std::uint64_t bytes = 0;
  for (const PlyProperty& p : element.properties) bytes += (p.count_type ? p.count_type : p.type)->bytes;
  if (!body.can_hold(element.count, bytes, element.properties.size()))
    throw IoError(file_message(body.path(), "PLY element '" + element.name + "' declares " +
                                                std::to_string(element.count) + " items, more than the " +
                                                std::to_string(body.bytes_left()) + " bytes left in the file hold"));
}

std::size_t find_property(const PlyElement& element, const std::string& name, bool list) {
  for (std::size_t i = 0; i < element.properties.size(); ++i)
    if (element.properties[i].name == name && (element.properties[i].count_type != nullptr) == list) return i;
  return element.properties.size();
}

void read_vertices(PlyBody& body, const PlyElement& element, const std::string& path, TriMesh& mesh) {
  std::size_t axis_property[3];
  for (int a = 0; a < 3; ++a) {
    axis_property[a] = find_property(element, std::string(1, char('x' + a)), false);
    if (axis_property[a] == element.properties.size())
      throw IoError(file_message(path, std::string("the PLY vertex element has no scalar property '") +
                                           char('x' + a) + "'"));
  }
  mesh.positions.resize(element.count);
  for (std::uint64_t v = 0; v < element.count; ++v) {
    body.locate(element.name, v);
    float* xyz = &mesh.positions[v].x;
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const PlyProperty& property = element.properties[p];
      const std::uint64_t n = property.count_type ? list_count(body, property) : 1;
      for (std::uint64_t i = 0; i < n; ++i) {
        const double value = body.value(*property.type);
        for (int a = 0; a < 3; ++a)
          if (p == axis_property[a]) xyz[a] = float(value);
      }
    }
  }
}

void read_faces(PlyBody& body, const PlyElement& element, const std::string& path, bool triangulate_polygons,
                TriMesh& mesh) {
  std::size_t indices = find_property(element, "vertex_indices", true);
  if (indices == element.properties.size()) indices = find_property(element, "vertex_index", true);
  if (indices == element.properties.size())
    throw IoError(file_message(path, "the PLY face element has no list property 'vertex_indices'"));
  mesh.triangles.reserve(element.count);
  std::vector<std::uint32_t> corners;
  for (std::uint64_t f = 0; f < element.count; ++f) {
    body.locate(element.name, f);
    for (std::size_t p = 0; p < element.properties.size(); ++p) {
      const PlyProperty& property = element.properties[p];
      const std::uint64_t n = property.count_type ? list_count(body, property) : 1;
      corners.clear();
      for (std::uint64_t i = 0; i < n; ++i) {
        const double value = body.value(*property.type);
        if (p != indices) continue;
        if (value < 0 || value != std::floor(value) || value > double(UINT32_MAX)) {
          std::ostringstream text;
          text << "vertex index " << value << " is not an index";
          body.fail(text.str());
        }
        corners.push_back(std::uint32_t(value));
      }
      if (p != indices) continue;
      if (corners.size() < 3) body.fail(std::to_string(corners.size()) + " corners; a face needs at least 3");
      append_polygon(corners, triangulate_polygons, path, f, mesh);
    }
  }
}

void skip_element(PlyBody& body, const PlyElement& element) {
  if (element.properties.empty()) return;  // nothing to read, however large its count
  for (std::uint64_t e = 0; e < element.count; ++e) {
    body.locate(element.name, e);
    for (const PlyProperty& property : element.properties) {
      const std::uint64_t n = property.count_type ? list_count(body, property) : 1;
      for (std::uint64_t i = 0; i < n; ++i) body.value(*property.type);
    }
  }
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const std::streamoff size = in ? std::streamoff(in.tellg()) : -1;
  std::string bytes(std::size_t(std::max<std::streamoff>(size, 0)), '\0');
  if (size < 0 || !in.seekg(0) || !in.read(bytes.data(), std::streamsize(bytes.size())))
    throw IoError(file_message(path, "could not read the file"));
  return bytes;
}

}  // namespace

TriMesh read_ply(const std::string& path, bool triangulate_polygons) {
  const std::string data = read_file(path);
  const PlyHeader header = parse_header(path, data);
  PlyBody body(path, data, header);
  TriMesh mesh;
  bool has_vertices = false;
  for (const PlyElement& element : header.elements) {
    require_element_fits(body, element);
    if (element.name == "vertex") {
      read_vertices(body, element, path, mesh);
      has_vertices = true;
    } else if (element.name == "face") {
      read_faces(body, element, path, triangulate_polygons, mesh);
    } else {
      skip_element(body, element);
    }
  }
  if (!has_vertices) throw IoError(file_message(path, "the PLY header declares no 'vertex' element"));
  return mesh;
}

}  // namespace raysift::mesh::detail
