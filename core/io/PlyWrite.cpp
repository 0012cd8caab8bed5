// Writing a tissue as PLY (see Ply.h for the layout).

#include "io/Ply.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/AtomicFile.h"

namespace tp {

namespace {

void validateForWriting(const CellComplex& cc, const Points& x) {
  const int V = cc.vertexCount(), T = cc.triangleCount(), W = cc.wallCount();
  const int C = cc.cellCount();
  auto bad = [](const std::string& m) { throw std::invalid_argument("writePly: " + m); };
  if (x.cols() != V)
    bad("positions have " + std::to_string(x.cols()) + " columns for " + std::to_string(V) +
        " vertices");
  if (static_cast<int>(cc.fixed.size()) != V) bad("fixed flags and vertices differ in number");
  if (static_cast<int>(cc.triangleWall.size()) != T) bad("triangleWall and triangles differ");
  for (int v = 0; v < V; ++v)
    if (!x.col(v).allFinite()) bad("vertex " + std::to_string(v) + " has a non-finite position");
  for (int t = 0; t < T; ++t) {
    if (cc.triangleWall[t] < 0 || cc.triangleWall[t] >= W)
      bad("triangle " + std::to_string(t) + ": bad wall");
    for (int k = 0; k < 3; ++k)
      if (cc.triangles[t][k] < 0 || cc.triangles[t][k] >= V)
        bad("triangle " + std::to_string(t) + ": vertex index out of range");
  }
  for (int w = 0; w < W; ++w) {
    const Wall& wall = cc.walls[w];
    if (wall.cell < -1 || wall.cell >= C || wall.neighbor < -1 || wall.neighbor >= C)
      bad("wall " + std::to_string(w) + ": cell index out of range");
  }
  // Labels identify cells in the file; a negative one would read back as "no cell".
  std::vector<int> labels = cc.cellLabels;
  std::sort(labels.begin(), labels.end());
  if (!labels.empty() && labels.front() < 0)
    bad("cell label " + std::to_string(labels.front()) + " is negative");
  const auto rep = std::adjacent_find(labels.begin(), labels.end());
  if (rep != labels.end()) bad("cell label " + std::to_string(*rep) + " is used twice");
}

template <class T>
void put(std::string& buf, T v) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
  buf.append(bytes, sizeof(T));
}

void putText(std::string& buf, double v) {
  char b[32];
  buf.append(b, std::to_chars(b, b + sizeof b, v).ptr);  // shortest form that reads back exactly
}

void putText(std::string& buf, int v) {
  char b[16];
  buf.append(b, std::to_chars(b, b + sizeof b, v).ptr);
}

}  // namespace

void writePly(std::ostream& out, const CellComplex& cc, const Points* positions, bool binary) {
  const Points& x = positions ? *positions : cc.rest;
  validateForWriting(cc, x);
  const int V = cc.vertexCount(), T = cc.triangleCount();
  std::string buf = "ply\nformat ";
  buf += binary ? "binary_little_endian 1.0\n" : "ascii 1.0\n";
  buf += "comment TissueProbe tissue, units um\n";
  buf += "comment face normal (right hand) points out of cell into neighbor; labels, -1 = none\n";
  buf += "comment faces with the same wall id form one wall\n";
  buf += "element vertex " + std::to_string(V) + "\n";
  buf += "property double x\nproperty double y\nproperty double z\nproperty uchar fixed\n";
  buf += "element face " + std::to_string(T) + "\n";
  buf += "property list uchar int vertex_indices\n";
  buf += "property int cell\nproperty int neighbor\nproperty int wall\n";
  buf += "end_header\n";
  auto label = [&](int c) { return c >= 0 ? cc.cellLabels[c] : -1; };
  auto flush = [&](bool force) {
    if (force || buf.size() > (1u << 20)) {
      out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
      buf.clear();
    }
  };
  for (int v = 0; v < V; ++v) {
    if (binary) {
      for (int k = 0; k < 3; ++k) put<double>(buf, x(k, v));
      put<std::uint8_t>(buf, cc.fixed[v] ? 1 : 0);
    } else {
      for (int k = 0; k < 3; ++k) {
        putText(buf, x(k, v));
        buf += ' ';
      }
      buf += cc.fixed[v] ? "1\n" : "0\n";
    }
    flush(false);
  }
  for (int t = 0; t < T; ++t) {
    const Wall& w = cc.walls[cc.triangleWall[t]];
    const int values[] = {label(w.cell), label(w.neighbor), cc.triangleWall[t]};
    if (binary) {
      put<std::uint8_t>(buf, 3);
      for (int k = 0; k < 3; ++k) put<std::int32_t>(buf, cc.triangles[t][k]);
      for (int v : values) put<std::int32_t>(buf, v);
    } else {
      buf += '3';
      for (int k = 0; k < 3; ++k) {
        buf += ' ';
        putText(buf, cc.triangles[t][k]);
      }
      for (int v : values) {
        buf += ' ';
        putText(buf, v);
      }
      buf += '\n';
    }
    flush(false);
  }
  flush(true);
}

void writePly(const std::string& path, const CellComplex& cc, const Points* positions,
              bool binary) {
  validateForWriting(cc, positions ? *positions : cc.rest);  // before touching the file
  writeFileAtomically(path, [&](std::ostream& out) { writePly(out, cc, positions, binary); });
}

}  // namespace tp
