#include "io/Ply.h"

// The tissue interpretation of a PLY table (see Ply.h for what is read and how faces become walls
// and cells); the table itself, its types and its errors are io/PlyTable.*.

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <span>
#include <sstream>
#include <string_view>
#include <tuple>
#include <unordered_map>

#include "io/PlyTable.h"

namespace tp {

namespace {

using ply::excerpt;

template <class Int>
std::string str(Int v) {
  return std::to_string(v);
}

std::string str(double v) {
  return ply::numberText(v);
}

// The faces as read, before they become a CellComplex.
struct RawFaces {
  std::vector<int> verts;                       // all polygons, concatenated
  std::vector<std::size_t> start{0};            // F + 1 offsets into verts
  std::vector<int> cell, neighbor, wall, line;  // per face (labels as in the file, -1 = none)
  int count() const { return static_cast<int>(cell.size()); }
  std::span<int> of(int f) { return {verts.data() + start[f], start[f + 1] - start[f]}; }
};

// Which property of an element plays which part (-1: absent).
struct VertexColumns {
  int x = -1, y = -1, z = -1, fixed = -1;
};
struct FaceColumns {
  int indices = -1, cell = -1, neighbor = -1, wall = -1;
};
struct VolumeColumns {  // openalea cells
  int faces = -1, label = -1;
};

class TissueReader {
 public:
  TissueReader(std::string data, std::string name) : table_(std::move(data), std::move(name)) {}

  CellComplex read(PlyInfo& info) {
    info.format = table_.formatName();
    findColumns(info);
    readData(info);
    return assemble(info);
  }

 private:
  [[noreturn]] void fail(const std::string& msg) const { table_.fail(msg); }

  std::string faceName(int f) const {
    if (table_.format() == ply::Format::Ascii)
      return "face " + str(f) + " (line " + str(faces_.line[f]) + ")";
    return "face " + str(f);
  }

  void findColumns(PlyInfo& info);
  void findVolumes(PlyInfo& info);
  std::vector<char> wanted(int e, std::initializer_list<int> columns) const;
  void readData(PlyInfo& info);
  void readVertices();
  void readFaces();
  void readVolumes();
  void applyVolumes(PlyInfo& info);
  int integral(double v, const char* what) const;

  CellComplex assemble(PlyInfo& info);
  void resolveLabels(std::vector<char>& keep, PlyInfo& info);
  bool closedSurface();
  void checkConsistentWinding();

  ply::TableReader table_;
  int vertexElement_ = -1, faceElement_ = -1, volumeElement_ = -1, vertexCount_ = 0;
  VertexColumns vc_;
  FaceColumns fc_;
  VolumeColumns oc_;
  struct Volume {
    int label = -1;
    std::vector<int> faces;
    std::string where;  // for messages
  };
  std::vector<Volume> volumes_;
  bool labelled_ = false, hasNeighbor_ = false, hasWall_ = false;
  std::vector<double> xyz_;
  std::vector<std::uint8_t> fixed_;
  RawFaces faces_;
};

void TissueReader::findColumns(PlyInfo& info) {
  const auto& elements = table_.elements();
  vertexElement_ = table_.findElement("vertex");
  faceElement_ = table_.findElement("face");
  if (vertexElement_ < 0) fail("no 'vertex' element in the header");
  if (faceElement_ < 0 || elements[faceElement_].count == 0) {
    std::string names;
    for (const ply::Element& e : elements) names += (names.empty() ? "" : ", ") + e.name;
    fail("no faces: a tissue needs an element 'face' with at least one face (this file has " +
         (names.empty() ? std::string("no elements") : "elements " + names) +
         "; a cell graph or point cloud is not a tissue)");
  }
  const ply::Element& ve = elements[vertexElement_];
  const ply::Element& fe = elements[faceElement_];
  if (ve.count > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
    fail("element 'vertex' declares " + str(ve.count) + " vertices, more than supported");
  if (fe.count > static_cast<std::uint64_t>(std::numeric_limits<int>::max()))
    fail("element 'face' declares " + str(fe.count) + " faces, more than supported");
  vertexCount_ = static_cast<int>(ve.count);

  // A property used for a part must be a list or a single value as the part needs.
  auto use = [&](const ply::Element& e, int k, bool list) {
    if (k < 0) return k;
    const ply::Property& p = e.properties[k];
    if (p.isList != list)
      fail("line " + str(p.line) + ": property '" + p.name + "' of element '" + e.name +
           "' must be " + (list ? "a list" : "a single value, not a list"));
    return k;
  };
  for (const char* c : {"x", "y", "z"})
    if (ve.find(c) < 0) fail("element 'vertex' has no property '" + std::string(c) + "'");
  vc_.x = use(ve, ve.find("x"), false);
  vc_.y = use(ve, ve.find("y"), false);
  vc_.z = use(ve, ve.find("z"), false);
  vc_.fixed = use(ve, ve.find("fixed"), false);

  int indices = fe.find("vertex_indices");
  if (indices < 0) indices = fe.find("vertex_index");
  if (indices < 0) fail("element 'face' has no list property 'vertex_indices' (or 'vertex_index')");
  fc_.indices = use(fe, indices, true);
  int cell = fe.find("cell");
  info.cellProperty = "cell";
  if (cell < 0) {
    // MorphoGraphX: the face label is the cell. Only a single value can be one.
    cell = fe.find("label");
    info.cellProperty = "label";
    if (cell >= 0 && fe.properties[cell].isList) cell = -1;
  }
  if (cell < 0) info.cellProperty.clear();
  labelled_ = cell >= 0;
  info.hadCellLabels = labelled_;
  fc_.cell = use(fe, cell, false);
  if (labelled_)
    fc_.neighbor = use(fe, fe.find("neighbor"), false);
  else if (fe.find("neighbor") >= 0)
    info.notes.push_back("faces have 'neighbor' but no cell labels: 'neighbor' ignored");
  fc_.wall = use(fe, fe.find("wall"), false);
  if (!labelled_) findVolumes(info);
  hasNeighbor_ = fc_.neighbor >= 0;
  hasWall_ = fc_.wall >= 0;

  const std::vector<char> vw = wanted(vertexElement_, {vc_.x, vc_.y, vc_.z, vc_.fixed});
  const std::vector<char> fw =
      wanted(faceElement_, {fc_.indices, fc_.cell, fc_.neighbor, fc_.wall});
  table_.checkReadable(vertexElement_, vw);
  table_.checkReadable(faceElement_, fw);
  for (const auto& [e, w] : {std::pair{vertexElement_, vw}, std::pair{faceElement_, fw}})
    for (std::size_t k = 0; k < w.size(); ++k)
      if (!w[k])
        info.ignoredProperties.push_back(elements[e].name + "." + elements[e].properties[k].name);
  for (int i = 0; i < static_cast<int>(elements.size()); ++i)
    if (i != vertexElement_ && i != faceElement_ && i != volumeElement_)
      info.ignoredElements.push_back(elements[i].name);
}

std::vector<char> TissueReader::wanted(int e, std::initializer_list<int> columns) const {
  std::vector<char> w(table_.elements()[e].properties.size(), 0);
  for (int k : columns)
    if (k >= 0) w[k] = 1;
  return w;
}

// openalea (PropertyTopomesh PLY): an element `volume` per cell, a list `face_index` of its
// faces and an integer `label`. Used for the cells when the faces carry no labels.
void TissueReader::findVolumes(PlyInfo& info) {
  const int i = table_.findElement("volume");
  if (i < 0) return;
  const ply::Element& e = table_.elements()[i];
  int faces = e.find("face_index");
  if (faces < 0) faces = e.find("face_indices");
  const int label = e.find("label");
  if (faces < 0 || label < 0 || !e.properties[faces].isList || e.properties[label].isList) {
    info.notes.push_back(
        "element 'volume' has no list 'face_index' and integer 'label': "
        "not used for cell labels");
    return;
  }
  // Every value up to the last one used must be readable (in binary, every value).
  const int last = table_.format() == ply::Format::Ascii
                       ? std::max(faces, label)
                       : static_cast<int>(e.properties.size()) - 1;
  for (int k = 0; k <= last; ++k)
    if (!e.properties[k].knownType()) {
      info.notes.push_back("element 'volume': property '" + e.properties[k].name + "' has type " +
                           excerpt(e.properties[k].typeText) +
                           ", not a PLY type, so the cells' faces cannot be read");
      return;
    }
  volumeElement_ = i;
  oc_ = {faces, label};
  labelled_ = true;
  info.hadCellLabels = true;
  info.cellProperty = "volume.label";
}

void TissueReader::readData(PlyInfo& info) {
  bool haveVertices = false, haveFaces = false;
  const auto& elements = table_.elements();
  for (int i = 0; i < static_cast<int>(elements.size()); ++i) {
    const bool used = i == vertexElement_ || i == faceElement_ || i == volumeElement_;
    if (!used && !table_.skippable(i)) {
      // Its instance size is unknown: nothing after it can be reached.
      if (haveVertices && haveFaces) {
        info.notes.push_back("stopped reading at element '" + elements[i].name +
                             "' (a property of unknown type); it and later elements ignored");
        break;
      }
      fail("element '" + elements[i].name + "' has a property of unknown type, so a binary file " +
           "cannot be read past it to the vertices or faces");
    }
    if (i == vertexElement_) {
      readVertices();
      haveVertices = true;
    } else if (i == faceElement_) {
      readFaces();
      haveFaces = true;
    } else if (i == volumeElement_) {
      readVolumes();
    } else {
      table_.skip(i);
    }
  }
  if (volumeElement_ >= 0) applyVolumes(info);
  if (const std::uint64_t rest = table_.trailingBytes())
    info.notes.push_back(str(rest) + " bytes after the last element ignored");
}

int TissueReader::integral(double v, const char* what) const {
  if (!(v == std::floor(v)) || v < std::numeric_limits<int>::min() ||
      v > std::numeric_limits<int>::max())
    table_.failAt(std::string(what) + " " + str(v) + " is not an integer in the range of int");
  return static_cast<int>(v);
}

void TissueReader::readVertices() {
  const ply::Element& e = table_.elements()[vertexElement_];
  // Counts are not trusted: reserve at most 65,536 vertices, grow beyond.
  const std::size_t n = std::min<std::uint64_t>(e.count, 1u << 16);
  xyz_.reserve(3 * n);
  fixed_.reserve(n);
  const int axes[3] = {vc_.x, vc_.y, vc_.z};
  table_.read(vertexElement_, wanted(vertexElement_, {vc_.x, vc_.y, vc_.z, vc_.fixed}),
              [&](std::uint64_t, const ply::Instance& in) {
                for (int a = 0; a < 3; ++a) {
                  const double c = in.values[axes[a]];
                  if (!std::isfinite(c))
                    table_.failAt(std::string("coordinate ") + "xyz"[a] + " is " + str(c) +
                                  " (not finite)");
                  if (std::abs(c) > kMaxCoordinate)  // 1 m: beyond any tissue; volumes overflow
                    table_.failAt(std::string("coordinate ") + "xyz"[a] + " is " + str(c) +
                                  " µm (at most " + str(kMaxCoordinate) + " µm in magnitude)");
                  xyz_.push_back(c);
                }
                fixed_.push_back(vc_.fixed >= 0 && in.values[vc_.fixed] != 0 ? 1 : 0);
              });
}

void TissueReader::readFaces() {
  std::vector<int> sorted;
  auto label = [](const ply::Instance& in, int k) { return k >= 0 ? in.values[k] : -1.0; };
  table_.read(faceElement_, wanted(faceElement_, {fc_.indices, fc_.cell, fc_.neighbor, fc_.wall}),
              [&](std::uint64_t, const ply::Instance& in) {
                const std::vector<double>& list = in.lists[fc_.indices];
                const std::size_t n = list.size();
                if (n < 3)
                  table_.failAt("a face with " + str(n) + " vertices (at least 3 are needed)");
                for (double v : list)
                  if (!(v >= 0 && v < vertexCount_ && v == std::floor(v)))
                    table_.failAt("vertex index " + str(v) + " out of range (the file has " +
                                  str(vertexCount_) + " vertices, 0.." + str(vertexCount_ - 1) +
                                  ")");
                sorted.assign(list.begin(), list.end());
                std::sort(sorted.begin(), sorted.end());
                const auto rep = std::adjacent_find(sorted.begin(), sorted.end());
                if (rep != sorted.end()) table_.failAt("the face repeats vertex " + str(*rep));
                faces_.verts.insert(faces_.verts.end(), list.begin(), list.end());
                faces_.start.push_back(faces_.verts.size());
                faces_.cell.push_back(integral(label(in, fc_.cell), "cell label"));
                faces_.neighbor.push_back(integral(label(in, fc_.neighbor), "neighbor label"));
                faces_.wall.push_back(integral(label(in, fc_.wall), "wall id"));
                faces_.line.push_back(table_.line());
              });
}

// One cell per instance: its label and the indices of its faces.
void TissueReader::readVolumes() {
  const std::uint64_t faceCount = table_.elements()[faceElement_].count;
  table_.read(volumeElement_, wanted(volumeElement_, {oc_.faces, oc_.label}),
              [&](std::uint64_t index, const ply::Instance& in) {
                Volume v;
                v.where = table_.format() == ply::Format::Ascii
                              ? "line " + str(table_.line()) + " (volume " + str(index) + ")"
                              : "element 'volume' index " + str(index);
                v.label = integral(in.values[oc_.label], "cell label");
                if (v.label < 0) table_.failAt("cell label " + str(v.label) + " is negative");
                for (double f : in.lists[oc_.faces]) {
                  if (!(f >= 0 && f < static_cast<double>(faceCount) && f == std::floor(f)))
                    table_.failAt("face index " + str(f) + " out of range (the file has " +
                                  str(faceCount) + " faces)");
                  v.faces.push_back(static_cast<int>(f));
                }
                volumes_.push_back(std::move(v));
              });
}

// A face listed by one volume has it as its cell, by two: cell and neighbour (the face's
// winding then says nothing of which is which; the first volume is taken as the cell).
void TissueReader::applyVolumes(PlyInfo& info) {
  int empty = 0;
  for (const Volume& v : volumes_) {
    if (v.faces.empty()) ++empty;
    for (int f : v.faces) {
      int& c = faces_.cell[f];
      int& n = faces_.neighbor[f];
      if (c == v.label || n == v.label) continue;
      if (c < 0) {
        c = v.label;
      } else if (n < 0) {
        n = v.label;
        hasNeighbor_ = true;
      } else {
        fail(v.where + ": face " + str(f) + " is already a wall of cells " + str(c) + " and " +
             str(n) + "; it cannot also bound cell " + str(v.label));
      }
    }
  }
  if (empty)
    info.notes.push_back(str(empty) + " volume(s) with no faces (cells without a wall) ignored");
}

enum class Winding { Same, Reversed, Other };

// How two faces over the same vertex set are wound relative to each other.
Winding compareWinding(std::span<const int> a, std::span<const int> b) {
  const std::size_t n = a.size();
  if (b.size() != n) return Winding::Other;
  const std::size_t p = static_cast<std::size_t>(std::find(b.begin(), b.end(), a[0]) - b.begin());
  if (p == n) return Winding::Other;
  bool same = true, reversed = true;
  for (std::size_t k = 0; k < n; ++k) {
    same = same && a[k] == b[(p + k) % n];
    reversed = reversed && a[k] == b[(p + n - k) % n];
  }
  return same ? Winding::Same : reversed ? Winding::Reversed : Winding::Other;
}

struct VectorHash {
  std::size_t operator()(const std::vector<int>& v) const {
    std::size_t h = v.size();
    for (int x : v) h = h * 1000003u ^ static_cast<std::size_t>(static_cast<unsigned>(x));
    return h;
  }
};

std::string cellsText(int cell, int neighbor) {
  return "cell " + str(cell) + ", neighbor " + str(neighbor);
}

// Normalises labels, and drops the second copy of every wall written from both sides.
void TissueReader::resolveLabels(std::vector<char>& keep, PlyInfo& info) {
  const int F = faces_.count();
  int turned = 0, twins = 0, duplicates = 0;
  for (int f = 0; f < F; ++f) {
    int& c = faces_.cell[f];
    int& n = faces_.neighbor[f];
    c = std::max(c, -1);
    n = std::max(n, -1);
    if (c >= 0 && c == n) fail(faceName(f) + ": cell and neighbor are both " + str(c));
    if (c < 0 && n >= 0) {  // only the cell on the far side: turn the face round
      const auto v = faces_.of(f);
      std::reverse(v.begin(), v.end());
      std::swap(c, n);
      ++turned;
    }
  }
  std::unordered_map<std::vector<int>, int, VectorHash> firstWithSet;
  firstWithSet.reserve(F);
  for (int f = 0; f < F; ++f) {
    const auto vf = faces_.of(f);
    std::vector<int> key(vf.begin(), vf.end());
    std::sort(key.begin(), key.end());
    const auto [it, inserted] = firstWithSet.try_emplace(std::move(key), f);
    if (inserted) continue;
    const int g = it->second;
    const int cf = faces_.cell[f], nf = faces_.neighbor[f];
    int& cg = faces_.cell[g];
    int& ng = faces_.neighbor[g];
    const std::string both = faceName(f) + " (" + cellsText(cf, nf) + ") and " + faceName(g) +
                             " (" + cellsText(cg, ng) + ")";
    switch (compareWinding(faces_.of(g), vf)) {
      case Winding::Other:
        fail(both + " have the same vertices in a different order");
      case Winding::Same:
        // (Without a `neighbor` property, g's neighbor may come from its twin.)
        if (cf != cg || (hasNeighbor_ && nf != ng))
          fail(both + " are the same face with different cells");
        ++duplicates;
        break;
      case Winding::Reversed:
        // The same wall seen from its other side.
        if (hasNeighbor_) {
          if (cf != ng || nf != cg) fail(both + " are one wall seen from both sides but disagree");
        } else {
          if (cf < 0 || cg < 0 || (ng >= 0 && ng != cf))
            fail(both + " are one wall seen from both sides but disagree");
          ng = cf;
        }
        ++twins;
        break;
    }
    keep[f] = 0;
  }
  if (turned) info.notes.push_back(str(turned) + " face(s) with only a neighbor turned round");
  if (twins) info.notes.push_back(str(twins) + " wall face(s) given from both sides merged");
  if (duplicates) info.notes.push_back(str(duplicates) + " duplicate face(s) dropped");
}

// True when the faces form a closed surface: every directed edge exactly once, with its reverse.
bool TissueReader::closedSurface() {
  std::vector<std::uint64_t> edges;
  edges.reserve(faces_.verts.size());
  auto key = [](int a, int b) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
           static_cast<std::uint32_t>(b);
  };
  for (int f = 0; f < faces_.count(); ++f) {
    const auto v = faces_.of(f);
    for (std::size_t k = 0; k < v.size(); ++k) edges.push_back(key(v[k], v[(k + 1) % v.size()]));
  }
  std::sort(edges.begin(), edges.end());
  if (std::adjacent_find(edges.begin(), edges.end()) != edges.end()) return false;
  for (std::uint64_t e : edges)
    if (!std::binary_search(edges.begin(), edges.end(), (e << 32) | (e >> 32))) return false;
  return true;
}

// An unlabelled surface that is closed but for the winding of some faces (every edge shared by
// exactly two faces, some pairs running it the same way) is refused with the faces named: read
// as a sheet it would silently lose its cell and its pressure.
void TissueReader::checkConsistentWinding() {
  struct Use {
    int a, b, face;
  };
  std::vector<Use> uses;
  for (int f = 0; f < faces_.count(); ++f) {
    const auto v = faces_.of(f);
    for (std::size_t k = 0; k < v.size(); ++k) {
      const int a = v[k], b = v[(k + 1) % v.size()];
      uses.push_back({std::min(a, b), std::max(a, b), f});
    }
  }
  std::sort(uses.begin(), uses.end(), [](const Use& x, const Use& y) {
    return std::tie(x.a, x.b, x.face) < std::tie(y.a, y.b, y.face);
  });
  std::vector<std::pair<int, int>> flipped;  // pairs of faces running an edge the same way
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    while (j < uses.size() && uses[j].a == uses[i].a && uses[j].b == uses[i].b) ++j;
    if (j - i != 2) return;  // an open or non-manifold surface: a sheet, as documented
    auto runsForward = [&](const Use& u) {
      const auto v = faces_.of(u.face);
      for (std::size_t k = 0; k < v.size(); ++k)
        if (v[k] == u.a && v[(k + 1) % v.size()] == u.b) return true;
      return false;
    };
    if (runsForward(uses[i]) == runsForward(uses[i + 1]))
      flipped.emplace_back(uses[i].face, uses[i + 1].face);
    i = j;
  }
  if (flipped.empty()) return;
  std::string list;
  for (std::size_t k = 0; k < std::min<std::size_t>(flipped.size(), 5); ++k)
    list += (k ? ", " : "") + std::to_string(flipped[k].first) + " and " +
            std::to_string(flipped[k].second);
  fail("the surface is closed but its faces are not wound consistently: " +
       std::to_string(flipped.size()) + " edge(s) run the same way in both of their faces (faces " +
       list + (flipped.size() > 5 ? ", …" : "") +
       "); wind every face the same way round (e.g. outward)");
}

CellComplex TissueReader::assemble(PlyInfo& info) {
  CellComplex cc;
  const int V = vertexCount_, F = faces_.count();
  cc.rest = Eigen::Map<const Points>(xyz_.data(), 3, V);
  cc.fixed = std::move(fixed_);
  std::vector<char> keep(F, 1);
  std::vector<int> labels;
  bool closed = false;
  if (labelled_) {
    resolveLabels(keep, info);
    for (int f = 0; f < F; ++f)
      if (keep[f])
        for (int c : {faces_.cell[f], faces_.neighbor[f]})
          if (c >= 0) labels.push_back(c);
    std::sort(labels.begin(), labels.end());
    labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
  } else if (closedSurface()) {
    closed = true;
    labels = {0};
    std::fill(faces_.cell.begin(), faces_.cell.end(), 0);
    std::fill(faces_.neighbor.begin(), faces_.neighbor.end(), -1);
  } else {
    checkConsistentWinding();
    std::fill(faces_.cell.begin(), faces_.cell.end(), -1);
    std::fill(faces_.neighbor.begin(), faces_.neighbor.end(), -1);
  }
  auto dense = [&](int label) {
    if (label < 0) return -1;
    return static_cast<int>(std::lower_bound(labels.begin(), labels.end(), label) - labels.begin());
  };

  std::unordered_map<int, int> wallOfId;           // file wall id -> wall
  std::map<std::pair<int, int>, int> wallOfCells;  // (cell, neighbor) -> wall of loose triangles
  std::vector<int> firstFace;                      // first face of each wall, for messages
  for (int f = 0; f < F; ++f) {
    if (!keep[f]) continue;
    const auto v = faces_.of(f);
    const int cell = dense(faces_.cell[f]), neighbor = dense(faces_.neighbor[f]);
    const int newWall = cc.wallCount();
    int w = newWall;
    if (hasWall_ && faces_.wall[f] >= 0) {
      w = wallOfId.try_emplace(faces_.wall[f], newWall).first->second;
      if (w != newWall) {
        Wall& wall = cc.walls[w];
        if (wall.cell != cell || wall.neighbor != neighbor)
          fail(faceName(f) + " is in wall " + str(faces_.wall[f]) + " with " +
               faceName(firstFace[w]) + " but bounds other cells (" +
               cellsText(faces_.cell[f], faces_.neighbor[f]) + " instead of " +
               cellsText(faces_.cell[firstFace[w]], faces_.neighbor[firstFace[w]]) + ")");
        wall.polygon.clear();  // several faces: no single boundary loop
      }
    } else if (v.size() == 3) {
      w = wallOfCells.try_emplace({cell, neighbor}, newWall).first->second;
    }
    if (w == newWall) {
      Wall wall;
      wall.cell = cell;
      wall.neighbor = neighbor;
      if (v.size() > 3) wall.polygon.assign(v.begin(), v.end());
      cc.walls.push_back(std::move(wall));
      firstFace.push_back(f);
    }
    if (v.size() == 3) {
      cc.triangles.emplace_back(v[0], v[1], v[2]);
      cc.triangleWall.push_back(w);
      continue;
    }
    for (const auto& t : triangulatePolygon(cc.rest, std::vector<int>(v.begin(), v.end()))) {
      cc.triangles.push_back(t);
      cc.triangleWall.push_back(w);
    }
  }
  cc.cellLabels = std::move(labels);
  if (closed && cellVolumes(cc, cc.rest)[0] < 0) {
    for (auto& t : cc.triangles) std::swap(t[1], t[2]);
    for (Wall& w : cc.walls) std::reverse(w.polygon.begin(), w.polygon.end());
    info.notes.push_back("closed surface wound inward: winding reversed");
  }
  if (!labelled_)
    info.notes.push_back(closed ? "no cell labels: a closed surface, read as one cell (label 0)"
                                : "no cell labels: an open surface, read as a sheet (no cell)");
  return cc;
}

}  // namespace

CellComplex readPly(std::istream& in, const std::string& nameForErrors, PlyInfo* info) {
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw PlyError(nameForErrors + ": read error");
  PlyInfo local;
  PlyInfo& out = info ? *info : local;
  out = PlyInfo{};
  TissueReader reader(std::move(buffer).str(), nameForErrors);
  return reader.read(out);
}

CellComplex readPly(const std::string& path, PlyInfo* info) {
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw PlyError(path + ": cannot open: " +
                   (err ? std::string(std::strerror(err)) : std::string("unknown error")));
  }
  return readPly(in, path, info);
}

}  // namespace tp
