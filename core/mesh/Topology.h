#pragma once
// Connectivity derived from a cell complex: edges, bending hinges and the outer surface.

#include <array>
#include <vector>

#include "mesh/CellComplex.h"

namespace tp {

/// Two triangles meeting at an edge. v = {x0, x1, x2, x3}: (x0, x1) is the shared edge,
/// triangle A = (x0, x1, x2) and triangle B = (x1, x0, x3) as seen by the dihedral-angle formula.
struct Hinge {
  std::array<int, 4> v;
  int triA = -1, triB = -1;
};

struct Topology {
  std::vector<std::array<int, 2>> edges;        // unique undirected edges (a < b)
  std::vector<std::vector<int>> edgeTriangles;  // triangles using each edge
  std::vector<Hinge> hinges;
  std::vector<int> outerTriangles;              // triangles with nothing on their far side
  std::vector<std::vector<int>> vertexTriangles;
};

/// Hinge rule (DESIGN.md §1): an edge of exactly two triangles carries a hinge; an edge of three or
/// more (a junction of walls) carries one only between its two outer-surface triangles, so the
/// epidermis bends as one sheet; otherwise none.
Topology buildTopology(const CellComplex& cc);

}  // namespace tp
