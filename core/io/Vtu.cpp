#include "io/Vtu.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <ostream>
#include <set>
#include <stdexcept>
#include <type_traits>

#include "io/AtomicFile.h"

namespace tp {

namespace {

std::string xmlEscaped(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

void appendBase64(std::string& out, const std::string& bytes) {
  static constexpr char digits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data());
  const std::size_t n = bytes.size();
  for (std::size_t i = 0; i < n; i += 3) {
    const std::uint32_t v = (std::uint32_t{b[i]} << 16) |
                            (i + 1 < n ? std::uint32_t{b[i + 1]} << 8 : 0u) |
                            (i + 2 < n ? std::uint32_t{b[i + 2]} : 0u);
    out += digits[(v >> 18) & 63];
    out += digits[(v >> 12) & 63];
    out += i + 1 < n ? digits[(v >> 6) & 63] : '=';
    out += i + 2 < n ? digits[v & 63] : '=';
  }
}

template <class T>
void appendNumber(std::string& out, T v) {
  char b[32];
  if constexpr (std::is_floating_point_v<T>) {
    if (std::isnan(v)) {  // to_chars may write "-nan"
      out += "nan";
      return;
    }
    out.append(b, std::to_chars(b, b + sizeof b, v).ptr);
  } else {
    out.append(b, std::to_chars(b, b + sizeof b, static_cast<long long>(v)).ptr);
  }
}

template <class T>
const char* vtkTypeName() {
  if constexpr (std::is_same_v<T, double>)
    return "Float64";
  else if constexpr (std::is_same_v<T, std::int64_t>)
    return "Int64";
  else if constexpr (std::is_same_v<T, std::int32_t>)
    return "Int32";
  else
    return "UInt8";
}

// One <DataArray>. Binary data are the native bytes, preceded by their size as UInt64, all in
// one base64 block (VTK's inline "binary" format without compression).
template <class T>
void appendArray(std::string& out, const std::string& name, int components,
                 const std::vector<T>& values, VtuEncoding encoding, const char* indent) {
  out += indent;
  out += "<DataArray type=\"";
  out += vtkTypeName<T>();
  out += "\" Name=\"" + xmlEscaped(name) + "\"";
  if (components != 1) out += " NumberOfComponents=\"" + std::to_string(components) + "\"";
  if (encoding == VtuEncoding::Base64) {
    out += " format=\"binary\">\n";
    out += indent;
    out += "  ";
    std::string bytes;
    const std::uint64_t size = values.size() * sizeof(T);
    bytes.resize(sizeof size + size);
    std::memcpy(bytes.data(), &size, sizeof size);
    if (size) std::memcpy(bytes.data() + sizeof size, values.data(), size);
    appendBase64(out, bytes);
  } else {
    out += " format=\"ascii\">\n";
    const std::size_t perLine = components > 0 ? 6 * static_cast<std::size_t>(components) : 6;
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (i % perLine == 0) {
        if (i) out += '\n';
        out += indent;
        out += "  ";
      } else {
        out += ' ';
      }
      appendNumber(out, values[i]);
    }
  }
  out += '\n';
  out += indent;
  out += "</DataArray>\n";
}

void validate(const CellComplex& cc, const Points& x, const std::vector<VtuField>& pointFields,
              const std::vector<VtuField>& cellFields) {
  auto bad = [](const std::string& m) { throw std::invalid_argument("writeVtu: " + m); };
  const int V = cc.vertexCount(), T = cc.triangleCount();
  if (x.cols() != V)
    bad("positions have " + std::to_string(x.cols()) + " columns for " + std::to_string(V) +
        " vertices");
  if (static_cast<int>(cc.fixed.size()) != V) bad("fixed flags and vertices differ in number");
  if (static_cast<int>(cc.triangleWall.size()) != T) bad("triangleWall and triangles differ");
  for (int t = 0; t < T; ++t) {
    const int w = cc.triangleWall[t];
    if (w < 0 || w >= cc.wallCount()) bad("triangle " + std::to_string(t) + ": bad wall index");
    const int c = cc.walls[w].cell;
    if (c < -1 || c >= cc.cellCount()) bad("wall " + std::to_string(w) + ": bad cell index");
    for (int k = 0; k < 3; ++k)
      if (cc.triangles[t][k] < 0 || cc.triangles[t][k] >= V)
        bad("triangle " + std::to_string(t) + ": vertex index out of range");
  }
  auto check = [&](const std::vector<VtuField>& fields, const char* kind, std::size_t count,
                   std::set<std::string> names) {
    for (const VtuField& f : fields) {
      const std::string what = std::string(kind) + " field '" + f.name + "'";
      if (f.name.empty()) bad(std::string(kind) + " field with an empty name");
      if (!names.insert(f.name).second) bad(what + ": name already used");
      if (f.components < 1) bad(what + ": components must be at least 1");
      const std::size_t expected = static_cast<std::size_t>(f.components) * count;
      if (f.values.size() != expected)
        bad(what + " has " + std::to_string(f.values.size()) + " values, expected " +
            std::to_string(f.components) + " x " + std::to_string(count) + " = " +
            std::to_string(expected));
    }
  };
  check(pointFields, "point", static_cast<std::size_t>(V), {"fixed"});
  check(cellFields, "cell", static_cast<std::size_t>(T), {"wall", "cell", "outer"});
}

}  // namespace

void writeVtu(std::ostream& out, const CellComplex& cc, const Points& positions,
              const std::vector<VtuField>& pointFields, const std::vector<VtuField>& cellFields,
              VtuEncoding encoding) {
  validate(cc, positions, pointFields, cellFields);
  const int V = cc.vertexCount(), T = cc.triangleCount();

  std::vector<double> points(positions.data(), positions.data() + 3 * static_cast<std::size_t>(V));
  std::vector<std::int64_t> connectivity, offsets;
  std::vector<std::uint8_t> types(T, 5), outer(T), fixed(V);
  std::vector<std::int32_t> wall(T), cell(T);
  connectivity.reserve(3 * static_cast<std::size_t>(T));
  offsets.reserve(T);
  for (int t = 0; t < T; ++t) {
    for (int k = 0; k < 3; ++k) connectivity.push_back(cc.triangles[t][k]);
    offsets.push_back(3 * static_cast<std::int64_t>(t + 1));
    wall[t] = cc.triangleWall[t];
    const int c = cc.walls[wall[t]].cell;
    cell[t] = c >= 0 ? cc.cellLabels[c] : -1;
    outer[t] = cc.isOuterTriangle(t) ? 1 : 0;
  }
  for (int v = 0; v < V; ++v) fixed[v] = cc.fixed[v] ? 1 : 0;

  std::string s;
  s += "<?xml version=\"1.0\"?>\n";
  s += "<!-- TissueProbe: triangles of the tissue; points in um -->\n";
  s += "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"";
  s += std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
  s += "\" header_type=\"UInt64\">\n";
  s += "  <UnstructuredGrid>\n";
  s += "    <Piece NumberOfPoints=\"" + std::to_string(V) + "\" NumberOfCells=\"" +
       std::to_string(T) + "\">\n";
  const char* in = "        ";
  s += "      <PointData>\n";
  appendArray(s, "fixed", 1, fixed, encoding, in);
  for (const VtuField& f : pointFields)
    appendArray(s, f.name, f.components, f.values, encoding, in);
  s += "      </PointData>\n";
  s += "      <CellData>\n";
  appendArray(s, "wall", 1, wall, encoding, in);
  appendArray(s, "cell", 1, cell, encoding, in);
  appendArray(s, "outer", 1, outer, encoding, in);
  for (const VtuField& f : cellFields) appendArray(s, f.name, f.components, f.values, encoding, in);
  s += "      </CellData>\n";
  s += "      <Points>\n";
  appendArray(s, "Points", 3, points, encoding, in);
  s += "      </Points>\n";
  s += "      <Cells>\n";
  appendArray(s, "connectivity", 1, connectivity, encoding, in);
  appendArray(s, "offsets", 1, offsets, encoding, in);
  appendArray(s, "types", 1, types, encoding, in);
  s += "      </Cells>\n";
  s += "    </Piece>\n";
  s += "  </UnstructuredGrid>\n";
  s += "</VTKFile>\n";
  out.write(s.data(), static_cast<std::streamsize>(s.size()));
}

void writeVtu(const std::string& path, const CellComplex& cc, const Points& positions,
              const std::vector<VtuField>& pointFields, const std::vector<VtuField>& cellFields,
              VtuEncoding encoding) {
  validate(cc, positions, pointFields, cellFields);  // before touching the file
  writeFileAtomically(path, [&](std::ostream& out) {
    writeVtu(out, cc, positions, pointFields, cellFields, encoding);
  });
}

}  // namespace tp
