#include "mesh/detail/off_reader.h"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string_view>
#include <vector>

#include "core/errors.h"
#include "mesh/detail/polygon_fan.h"

namespace raysift::mesh::detail {
namespace {

/// The file's meaningful lines (comments and blank lines dropped) with their 1-based numbers.
struct OffLines {
  std::vector<std::string> text;
  std::vector<int> number;
};

OffLines read_lines(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw IoError(file_message(path, "could not read the file"));
  OffLines lines;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    line.erase(std::min(line.find('#'), line.size()));
    if (line.find_first_not_of(" \t\r\f\v") == std::string::npos) continue;
    lines.text.push_back(line);
    lines.number.push_back(number);
  }
  return lines;
}

/// Splits one line into whitespace-separated tokens and parses them on request.
class OffLine {
 public:
  OffLine(const std::string& path, const OffLines& lines, std::size_t index)
      : path_(path), number_(lines.number[index]) {
    std::istringstream in(lines.text[index]);
    for (std::string token; in >> token;) tokens_.push_back(token);
  }

  std::size_t size() const { return tokens_.size(); }
  const std::string& token(std::size_t i) const { return tokens_[i]; }

  [[noreturn]] void fail(const std::string& message) const {
    throw IoError(path_ + ":" + std::to_string(number_) + ": " + message);
  }

  float real(std::size_t i) const {
    float v = 0;
    if (i >= tokens_.size()) fail("expected " + std::to_string(i + 1) + " numbers, found " + std::to_string(size()));
    const std::string& t = tokens_[i];
    const auto [stop, error] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (error != std::errc() || stop != t.data() + t.size()) fail("'" + t.substr(0, 40) + "' is not a number");
    return v;
  }

  std::uint64_t count(std::size_t i, std::uint64_t limit, const char* what) const {
    if (i >= tokens_.size()) fail(std::string("expected ") + what + " after " + std::to_string(size()) + " numbers");
    const std::string& t = tokens_[i];
    std::uint64_t v = 0;
    const auto [stop, error] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (error != std::errc() || stop != t.data() + t.size() || v > limit)
      fail(std::string(what) + " '" + t.substr(0, 40) + "' is not an integer in [0, " + std::to_string(limit) + "]");
    return v;
  }

 private:
  const std::string& path_;
  int number_;
  std::vector<std::string> tokens_;
};

/// [ST][C][N]OFF, optionally followed by the counts on the same line.
void check_keyword(const OffLine& first) {
  const std::string& keyword = first.token(0);
  const std::size_t off = keyword.size() >= 3 ? keyword.size() - 3 : std::string::npos;
  std::string_view prefix(keyword.data(), off == std::string::npos ? 0 : off);
  if (prefix.rfind("ST", 0) == 0) prefix.remove_prefix(2);
  if (!prefix.empty() && prefix.front() == 'C') prefix.remove_prefix(1);
  if (!prefix.empty() && prefix.front() == 'N') prefix.remove_prefix(1);
  if (off == std::string::npos || keyword.compare(off, 3, "OFF") != 0 || !prefix.empty())
    first.fail("'" + keyword.substr(0, 40) + "' is not an OFF keyword (binary, 4D and nOFF files are not supported)");
  if (first.size() > 1 && first.token(1) == "BINARY") first.fail("binary OFF is not supported; convert it to ASCII");
}

void add_face(const OffLine& line, std::uint64_t face, bool triangulate_polygons, const std::string& path,
              TriMesh& mesh) {
  const std::uint64_t corners = line.count(0, line.size() - 1, "corner count");
  if (corners < 3) line.fail("face " + std::to_string(face) + " has " + std::to_string(corners) +
                             " corners; a face needs at least 3");
  std::vector<std::uint32_t> v(corners);
  for (std::uint64_t i = 0; i < corners; ++i) v[i] = std::uint32_t(line.count(1 + i, UINT32_MAX, "vertex index"));
  append_polygon(v, triangulate_polygons, path, face, mesh);
}

}  // namespace

TriMesh read_off(const std::string& path, bool triangulate_polygons) {
  const OffLines lines = read_lines(path);
  if (lines.text.empty()) throw IoError(file_message(path, "empty file; expected an 'OFF' line"));
  const OffLine first(path, lines, 0);
  check_keyword(first);
  std::size_t next = 1;
  const bool counts_on_first_line = first.size() > 1;
  const OffLine counts = counts_on_first_line || next >= lines.text.size() ? first : OffLine(path, lines, next++);
  const std::size_t at = counts_on_first_line ? 1 : 0;
  const std::uint64_t left = lines.text.size() - next;  // each vertex and face has its own line
  const std::uint64_t vertices = counts.count(at, left, "vertex count");
  const std::uint64_t faces = counts.count(at + 1, left - vertices, "face count");
  TriMesh mesh;
  mesh.positions.resize(vertices);
  for (std::uint64_t v = 0; v < vertices; ++v) {
    const OffLine line(path, lines, next++);
    mesh.positions[v] = {line.real(0), line.real(1), line.real(2)};
  }
  mesh.triangles.reserve(faces);
  for (std::uint64_t f = 0; f < faces; ++f) add_face(OffLine(path, lines, next++), f, triangulate_polygons, path, mesh);
  return mesh;
}

}  // namespace raysift::mesh::detail
