// Pre-parse of STL, PLY and OBJ files (mesh_file_check.h): counts, sizes, numbers
// and indices, so that assimp is only handed files it reads without aborting.
#include "rocklab/geometry/mesh_file_check.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string_view>
#include <vector>

namespace rocklab::geometry {

namespace {

// STL is little-endian and so is every machine rocklab is built on (x86-64, arm64):
// binary values are copied as they are.
static_assert(std::endian::native == std::endian::little, "mesh_file_check.cpp reads little-endian files");

constexpr std::uintmax_t kMaxFileBytes = std::uintmax_t{2} << 30;

/// A problem found: the sentence meshFileProblem returns.
struct Bad {
  std::string what;
};

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::vector<std::string_view> tokens(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

/// The whole token as a number, or nothing.
std::optional<double> number(std::string_view token) {
  if (token.size() > 1 && token.front() == '+') token.remove_prefix(1);
  double v = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
  if (ec != std::errc() || end != token.data() + token.size()) return std::nullopt;
  return v;
}

/// Reads the lines of a text body one by one, counting them for messages.
class Lines {
 public:
  Lines(std::string_view text, std::size_t first_line) : text_(text), line_(first_line - 1) {}
  /// The next line that is not blank; false at the end.
  bool next(std::string_view& line) {
    while (pos_ < text_.size()) {
      std::size_t end = text_.find('\n', pos_);
      if (end == std::string_view::npos) end = text_.size();
      line = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_;
      if (line.find_first_not_of(" \t\r\f\v") != std::string_view::npos) return true;
    }
    return false;
  }
  std::size_t number() const { return line_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0, line_;
};

void checkCount(double count, const char* what) {
  if (count > kMaxMeshFileTriangles) {
    std::ostringstream s;
    s << "holds " << count << " " << what << ", more than the " << kMaxMeshFileTriangles
      << " a mesh may have (about 100 bytes each while read)";
    throw Bad{s.str()};
  }
}

// --- STL ---------------------------------------------------------------------------------

void checkBinaryStl(std::string_view data) {
  std::uint32_t n = 0;
  std::memcpy(&n, data.data() + 80, 4);
  if (n == 0) throw Bad{"binary STL with 0 triangles"};
  checkCount(n, "triangles");
  const double needed = 84.0 + 50.0 * n;
  if (needed > static_cast<double>(data.size()))
    throw Bad{"binary STL whose header says " + std::to_string(n) + " triangles (" +
              std::to_string(static_cast<std::uint64_t>(needed)) + " bytes) but the file has " +
              std::to_string(data.size()) + " bytes: truncated, or not an STL"};
  for (std::uint32_t t = 0; t < n; ++t) {
    float f[9];
    std::memcpy(f, data.data() + 84 + 50 * static_cast<std::size_t>(t) + 12, sizeof f);
    for (float v : f)
      if (!std::isfinite(v)) throw Bad{"binary STL triangle " + std::to_string(t) + " has a non-finite coordinate"};
  }
}

void checkAsciiStl(std::string_view text) {
  Lines lines(text, 1);
  std::string_view line;
  std::size_t facets = 0, vertices_in_loop = 0;
  bool in_loop = false;
  while (lines.next(line)) {
    const auto tok = tokens(line);
    const std::string word = lower(std::string(tok.front()));
    const std::string at = "ascii STL line " + std::to_string(lines.number()) + ": ";
    if (word == "outer") {
      in_loop = true;
      vertices_in_loop = 0;
    } else if (word == "vertex") {
      if (!in_loop) throw Bad{at + "a vertex outside an 'outer loop'"};
      if (tok.size() != 4) throw Bad{at + "a vertex needs 3 coordinates"};
      for (std::size_t k = 1; k < 4; ++k)
        if (const auto v = number(tok[k]); !v || !std::isfinite(*v))
          throw Bad{at + "'" + std::string(tok[k]) + "' is not a finite number"};
      ++vertices_in_loop;
    } else if (word == "endloop") {
      if (!in_loop) throw Bad{at + "'endloop' without 'outer loop'"};
      if (vertices_in_loop != 3)
        throw Bad{at + "a facet with " + std::to_string(vertices_in_loop) + " vertices (STL facets have 3)"};
      in_loop = false;
      checkCount(static_cast<double>(++facets), "triangles");
    } else if (word != "solid" && word != "facet" && word != "endfacet" && word != "endsolid") {
      throw Bad{at + "unexpected '" + std::string(tok.front()) + "'"};
    }
  }
  if (in_loop) throw Bad{"ascii STL ends inside a facet (truncated)"};
  if (facets == 0) throw Bad{"ascii STL without a facet"};
}

void checkStl(std::string_view data) {
  if (data.size() >= 84) {
    std::uint32_t n = 0;
    std::memcpy(&n, data.data() + 80, 4);
    // A binary STL may start with "solid" too: its size decides.
    if (84.0 + 50.0 * n == static_cast<double>(data.size())) return checkBinaryStl(data);
  }
  const auto start = data.find_first_not_of(" \t\r\n");
  if (start != std::string_view::npos && lower(std::string(data.substr(start, 5))) == "solid" &&
      data.find('\0') == std::string_view::npos)
    return checkAsciiStl(data);
  if (data.size() < 84) throw Bad{"too short for a binary STL (" + std::to_string(data.size()) + " bytes; the header alone is 84) and not an ascii STL"};
  checkBinaryStl(data);
}

// --- PLY ---------------------------------------------------------------------------------

enum class Format { Ascii, Little, Big };

struct Property {
  std::string name;
  int size = 0;             // bytes of the value (of each item for a list)
  bool integer = false, is_signed = false;
  int count_size = 0;       // > 0: a list, bytes of its count
  bool count_signed = false;
};

struct Element {
  std::string name;
  double count = 0;
  std::vector<Property> properties;
};

/// Bytes, integer and signedness of a PLY type name; size 0 when unknown.
Property typeOf(const std::string& t) {
  if (t == "char" || t == "int8") return {"", 1, true, true};
  if (t == "uchar" || t == "uint8") return {"", 1, true, false};
  if (t == "short" || t == "int16") return {"", 2, true, true};
  if (t == "ushort" || t == "uint16") return {"", 2, true, false};
  if (t == "int" || t == "int32") return {"", 4, true, true};
  if (t == "uint" || t == "uint32") return {"", 4, true, false};
  if (t == "float" || t == "float32") return {"", 4, false, true};
  if (t == "double" || t == "float64") return {"", 8, false, true};
  return {};
}

struct PlyHeader {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  std::size_t body_offset = 0, body_line = 0;  // where the data starts
};

PlyHeader readPlyHeader(std::string_view data) {
  PlyHeader h;
  std::size_t pos = 0, line_no = 0;
  bool format_seen = false;
  while (true) {
    const std::size_t end = data.find('\n', pos);
    if (end == std::string_view::npos) throw Bad{"PLY header without 'end_header'"};
    std::string_view line = data.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    const auto tok = tokens(line);
    const std::string at = "PLY header line " + std::to_string(line_no) + ": ";
    if (line_no == 1) {
      if (tok.size() != 1 || tok[0] != "ply") throw Bad{"not a PLY file (the first line is not 'ply')"};
      continue;
    }
    if (tok.empty() || tok[0] == "comment" || tok[0] == "obj_info") continue;
    if (tok[0] == "end_header") break;
    if (tok[0] == "format") {
      if (tok.size() != 3) throw Bad{at + "expected 'format ascii|binary_little_endian|binary_big_endian 1.0'"};
      if (tok[1] == "ascii") h.format = Format::Ascii;
      else if (tok[1] == "binary_little_endian") h.format = Format::Little;
      else if (tok[1] == "binary_big_endian") h.format = Format::Big;
      else throw Bad{at + "unknown format '" + std::string(tok[1]) + "'"};
      format_seen = true;
    } else if (tok[0] == "element") {
      const auto count = tok.size() == 3 ? number(tok[2]) : std::nullopt;
      if (!count || *count < 0 || *count != std::floor(*count))
        throw Bad{at + "expected 'element NAME COUNT' with a whole COUNT >= 0"};
      h.elements.push_back({std::string(tok[1]), *count, {}});
    } else if (tok[0] == "property") {
      if (h.elements.empty()) throw Bad{at + "a property before any element"};
      Property p;
      if (tok.size() == 5 && tok[1] == "list") {
        const Property c = typeOf(std::string(tok[2]));
        p = typeOf(std::string(tok[3]));
        if (c.size == 0 || !c.integer || p.size == 0)
          throw Bad{at + "expected 'property list COUNT_TYPE ITEM_TYPE NAME' with PLY types"};
        p.count_size = c.size;
        p.count_signed = c.is_signed;
      } else if (tok.size() == 3) {
        p = typeOf(std::string(tok[1]));
        if (p.size == 0) throw Bad{at + "unknown property type '" + std::string(tok[1]) + "'"};
      } else {
        throw Bad{at + "expected 'property TYPE NAME' or 'property list COUNT_TYPE ITEM_TYPE NAME'"};
      }
      p.name = std::string(tok.back());
      h.elements.back().properties.push_back(p);
    } else {
      throw Bad{at + "unexpected '" + std::string(tok[0]) + "'"};
    }
  }
  if (!format_seen) throw Bad{"PLY header without a 'format' line"};
  h.body_offset = pos;
  h.body_line = line_no + 1;
  return h;
}

/// What the PLY must hold for a surface: vertices with x, y, z, faces with an index list.
struct PlyLayout {
  double vertices = 0, faces = 0;
};

PlyLayout plyLayout(const PlyHeader& h) {
  PlyLayout layout;
  bool has_vertex = false, has_face = false;
  for (const Element& e : h.elements) {
    if (e.name == "vertex") {
      has_vertex = true;
      layout.vertices = e.count;
      for (const char* axis : {"x", "y", "z"})
        if (std::none_of(e.properties.begin(), e.properties.end(),
                         [&](const Property& p) { return p.name == axis && p.count_size == 0; }))
          throw Bad{std::string("PLY vertex element without a '") + axis + "' property"};
    }
    if (e.name == "face") {
      has_face = true;
      layout.faces = e.count;
      if (std::none_of(e.properties.begin(), e.properties.end(), [](const Property& p) {
            return p.count_size > 0 && p.integer && (p.name == "vertex_indices" || p.name == "vertex_index");
          }))
        throw Bad{"PLY face element without an integer 'vertex_indices' list"};
    }
  }
  if (!has_vertex || !has_face) throw Bad{"PLY without a 'vertex' and a 'face' element"};
  checkCount(layout.vertices, "vertices");
  checkCount(layout.faces, "faces");
  return layout;
}

/// Checks one value of `element`'s row `row`: finite coordinates, face indices in range.
struct ValueCheck {
  const PlyLayout& layout;
  void operator()(const Element& e, const Property& p, double v, bool list_item,
                  const std::string& where) const {
    if (!std::isfinite(v)) throw Bad{where + "a non-finite value of '" + p.name + "'"};
    if (e.name == "face" && list_item && (p.name == "vertex_indices" || p.name == "vertex_index") &&
        (v < 0 || v >= layout.vertices)) {
      std::ostringstream s;
      s << where << "refers to vertex " << v << ", but the header declares "
        << layout.vertices << " vertices";
      throw Bad{s.str()};
    }
  }
};

void checkListCount(const Element& e, const Property& p, double count, const std::string& where) {
  if (count < 0 || count != std::floor(count)) throw Bad{where + "list '" + p.name + "' has a count that is not a whole number >= 0"};
  if (e.name == "face" && (p.name == "vertex_indices" || p.name == "vertex_index") && count < 3)
    throw Bad{where + "a face with " + std::to_string(static_cast<long long>(count)) +
              " vertices (at least 3); does the header under-state a count before it?"};
}

void checkAsciiPly(std::string_view data, const PlyHeader& h, const PlyLayout& layout) {
  Lines lines(data.substr(h.body_offset), h.body_line);
  const ValueCheck check{layout};
  std::string_view line;
  for (const Element& e : h.elements)
    for (double row = 0; row < e.count; ++row) {
      if (!lines.next(line)) {
        std::ostringstream s;
        s << "PLY ends after " << row << " of the " << e.count << " '" << e.name
          << "' rows its header declares (is the count too large?)";
        throw Bad{s.str()};
      }
      const auto tok = tokens(line);
      const std::string where = "PLY line " + std::to_string(lines.number()) + " (" + e.name + " " +
                                std::to_string(static_cast<long long>(row)) + "): ";
      std::size_t k = 0;
      auto take = [&]() -> double {
        if (k >= tok.size()) throw Bad{where + "too few values for the header's properties"};
        const auto v = number(tok[k]);
        if (!v) throw Bad{where + "'" + std::string(tok[k]) + "' is not a number"};
        ++k;
        return *v;
      };
      for (const Property& p : e.properties) {
        if (p.count_size == 0) {
          check(e, p, take(), false, where);
          continue;
        }
        const double count = take();
        checkListCount(e, p, count, where);
        for (double i = 0; i < count; ++i) check(e, p, take(), true, where);
      }
      if (k != tok.size())
        throw Bad{where + std::to_string(tok.size() - k) + " more value(s) than the header's properties " +
                  "(does the header under-state a count?)"};
    }
  if (lines.next(line))
    throw Bad{"PLY line " + std::to_string(lines.number()) +
              ": data after the last row the header declares (does the header under-state a count?)"};
}

double readBinary(std::string_view data, std::size_t& pos, int size, bool integer, bool is_signed, bool big,
                  const std::string& where) {
  if (pos + static_cast<std::size_t>(size) > data.size())
    throw Bad{where + "the file ends inside it (truncated, or the header over-states a count)"};
  unsigned char b[8];
  std::memcpy(b, data.data() + pos, static_cast<std::size_t>(size));
  pos += static_cast<std::size_t>(size);
  if (big) std::reverse(b, b + size);
  if (!integer) {
    if (size == 4) {
      float f;
      std::memcpy(&f, b, 4);
      return f;
    }
    double d;
    std::memcpy(&d, b, 8);
    return d;
  }
  std::uint64_t u = 0;
  std::memcpy(&u, b, static_cast<std::size_t>(size));
  if (is_signed && size < 8 && (u >> (8 * size - 1)) & 1) u |= ~std::uint64_t{0} << (8 * size);
  return is_signed ? static_cast<double>(static_cast<std::int64_t>(u)) : static_cast<double>(u);
}

void checkBinaryPly(std::string_view data, const PlyHeader& h, const PlyLayout& layout) {
  const bool big = h.format == Format::Big;
  const ValueCheck check{layout};
  std::size_t pos = h.body_offset;
  for (const Element& e : h.elements)
    for (double row = 0; row < e.count; ++row) {
      const std::string where = "PLY " + e.name + " " + std::to_string(static_cast<long long>(row)) + ": ";
      for (const Property& p : e.properties) {
        if (p.count_size == 0) {
          check(e, p, readBinary(data, pos, p.size, p.integer, p.is_signed, big, where), false, where);
          continue;
        }
        const double count = readBinary(data, pos, p.count_size, true, p.count_signed, big, where);
        checkListCount(e, p, count, where);
        for (double i = 0; i < count; ++i)
          check(e, p, readBinary(data, pos, p.size, p.integer, p.is_signed, big, where), true, where);
      }
    }
  if (data.substr(pos).find_first_not_of("\r\n") != std::string_view::npos)
    throw Bad{"PLY has " + std::to_string(data.size() - pos) +
              " bytes after the last row its header declares (does the header under-state a count?)"};
}

void checkPly(std::string_view data) {
  const PlyHeader h = readPlyHeader(data);
  const PlyLayout layout = plyLayout(h);
  if (h.format == Format::Ascii) checkAsciiPly(data, h, layout);
  else checkBinaryPly(data, h, layout);
}

// --- OBJ ---------------------------------------------------------------------------------

void checkObj(std::string_view text) {
  // Vertices first (a face may refer to a vertex defined after it), then the faces.
  double vertices = 0, faces = 0;
  {
    Lines lines(text, 1);
    std::string_view line;
    while (lines.next(line)) {
      const auto tok = tokens(line);
      if (tok.front() != "v") continue;
      if (tok.size() < 4) throw Bad{"OBJ line " + std::to_string(lines.number()) + ": a vertex needs 3 coordinates"};
      for (std::size_t k = 1; k < tok.size(); ++k)
        if (const auto v = number(tok[k]); !v || !std::isfinite(*v))
          throw Bad{"OBJ line " + std::to_string(lines.number()) + ": '" + std::string(tok[k]) +
                    "' is not a finite number"};
      checkCount(++vertices, "vertices");
    }
  }
  Lines lines(text, 1);
  std::string_view line;
  double defined = 0;  // vertices before this line: what a negative (relative) index counts back over
  while (lines.next(line)) {
    const auto tok = tokens(line);
    if (tok.front() == "v") ++defined;
    if (tok.front() != "f") continue;
    const std::string at = "OBJ line " + std::to_string(lines.number()) + ": ";
    if (tok.size() < 4) throw Bad{at + "a face with " + std::to_string(tok.size() - 1) + " vertex reference(s) (at least 3)"};
    for (std::size_t k = 1; k < tok.size(); ++k) {
      const std::string_view ref = tok[k].substr(0, tok[k].find('/'));
      const auto i = number(ref);
      if (!i || *i != std::floor(*i) || *i == 0 || (*i > 0 && *i > vertices) || (*i < 0 && -*i > defined)) {
        std::ostringstream s;
        s << at << "face vertex '" << tok[k] << "' is not a vertex of the file (1 to " << vertices
          << ", or -1 to -" << defined << " counting back)";
        throw Bad{s.str()};
      }
    }
    checkCount(++faces, "faces");
  }
  if (faces == 0) throw Bad{"OBJ that contains no triangles (no 'f' line)"};
}

}  // namespace

std::string meshFileProblem(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return "does not exist";
  if (std::filesystem::is_directory(path, ec)) return "is a directory, not a mesh file";
  const std::string ext = lower(std::filesystem::path(path).extension().string());
  if (ext != ".stl" && ext != ".ply" && ext != ".obj")
    return "unknown extension '" + ext + "': STL, PLY and OBJ files are read (.stl, .ply, .obj)";
  std::ifstream in(path, std::ios::binary);
  if (!in) return "cannot be opened for reading";
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return "cannot be read: " + ec.message();
  if (size > kMaxFileBytes)
    return "is " + std::to_string(size) + " bytes; mesh files of up to 2 GB are read";
  std::string data(size, '\0');
  if (!in.read(data.data(), static_cast<std::streamsize>(size))) return "cannot be read to its end";
  try {
    if (ext == ".stl") checkStl(data);
    else if (ext == ".ply") checkPly(data);
    else checkObj(data);
  } catch (const Bad& bad) {
    return bad.what;
  }
  return "";
}

}  // namespace rocklab::geometry
