#pragma once
// Reading and writing a tissue as a PLY file (DESIGN.md §3), ASCII or binary. Units: µm.
//
// What the reader takes from a file (everything else is read past and reported in PlyInfo):
//  - `element vertex`: `x y z` (any numeric type, finite), optional `fixed` (nonzero = clamped).
//  - `element face`: a list `vertex_indices` (or `vertex_index`), polygons allowed; optional
//    integer `cell`, `neighbor` and `wall`. MorphoGraphX names the cell of a face `label`; it is
//    used as the cell when there is no `cell` property.
//  - `element volume` (openalea PropertyTopomesh): without face labels, a list `face_index` and
//    an integer `label` per cell give the cells: a face listed by one volume has it as its cell,
//    by two as cell and neighbor.
// How faces become walls and cells:
//  - With cell labels: a face's right-hand normal points out of `cell` into `neighbor` (labels;
//    any negative value = none; without a `neighbor` property every face has none unless its
//    twin says otherwise, see below). Dense cell indices follow the labels in ascending order, and
//    every label that appears as `cell` or as `neighbor` becomes a cell (a cell may be described
//    entirely from the other side of its walls). A face with no cell but a neighbor is turned
//    round (winding reversed, cell and neighbor swapped), so that `cell == -1` only marks sheets.
//    A wall may be written once (with its neighbor) or twice, once from each side with opposite
//    winding; the second copy is recognised (same vertices) and dropped, after checking that the
//    two agree (or, without a `neighbor` property, it supplies the neighbor of the first).
//  - Without cell labels: if the faces form one closed, consistently oriented surface (every edge
//    used exactly once in each direction) they bound one cell (label 0, the winding reversed if
//    needed to make its volume positive); otherwise they form an open sheet (cell -1).
//  - Walls: faces with the same `wall` id (>= 0) form one wall (their cells must agree). Without
//    an id a polygon is a wall of its own, and triangles with the same cell and neighbor form one
//    wall (so a triangulated interface between two cells is one wall). Polygons are triangulated
//    with tp::triangulatePolygon; triangles keep the file's face order.
// Malformed files throw tp::PlyError naming the file and the line (ASCII) or the element and
// index (binary). Counts in the header are never trusted for allocation. The generic part (header,
// types, values, their errors) is io/PlyTable.h; this file gives the table its tissue meaning.

#include <iosfwd>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/PlyTable.h"  // PlyError
#include "mesh/CellComplex.h"

namespace tp {

/// What a read found besides the tissue.
struct PlyInfo {
  std::string format;                          // "ascii", "binary_little_endian", ...
  std::vector<std::string> ignoredElements;    // e.g. "edge", "volume"
  std::vector<std::string> ignoredProperties;  // "element.property", e.g. "vertex.signal"
  bool hadCellLabels = false;                  // faces carried `cell` (or `label`)
  std::string cellProperty;                    // "cell", "label", "volume.label" or empty
  std::vector<std::string> notes;              // merged duplicates, reversed winding, ...
};

/// Reads a tissue from a PLY file. Throws PlyError (also when the file cannot be opened).
CellComplex readPly(const std::string& path, PlyInfo* info = nullptr);
/// Same from a stream; `nameForErrors` starts every error message.
CellComplex readPly(std::istream& in, const std::string& nameForErrors, PlyInfo* info = nullptr);

/// Writes the tissue at `positions` (default: the rest positions), atomically: vertices
/// `double x y z`, `uchar fixed`; one face per triangle with `list uchar int vertex_indices`,
/// `int cell` and `int neighbor` (labels, -1 = none) and `int wall` (wall index). Reading the file
/// back gives the same vertices (bit for bit, also in ASCII), fixed flags, triangles, walls,
/// cell labels and neighbors; polygon loops (Wall::polygon) are not stored. Binary files are
/// little endian. Throws std::invalid_argument for an inconsistent complex (sizes, indices,
/// negative or repeated labels, non-finite positions), std::runtime_error if writing fails.
void writePly(const std::string& path, const CellComplex& cc, const Points* positions = nullptr,
              bool binary = false);
/// Same to a stream (not atomic; open it in binary mode for a binary file).
void writePly(std::ostream& out, const CellComplex& cc, const Points* positions = nullptr,
              bool binary = false);

}  // namespace tp
