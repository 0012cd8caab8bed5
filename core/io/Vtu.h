#pragma once
// Writing a deformed tissue for ParaView: a VTK XML UnstructuredGrid (.vtu) whose cells are the
// triangles (VTK_TRIANGLE = 5). Units: µm for the points; fields carry whatever units they have.

#include <iosfwd>
#include <string>
#include <vector>

#include "mesh/CellComplex.h"

namespace tp {

/// A data array attached to the points or the triangles: `values` holds `components` numbers per
/// point (or triangle), point after point: size = components × count.
struct VtuField {
  std::string name;
  int components = 1;
  std::vector<double> values;
};

/// How the data arrays are stored. Base64 is exact and compact, and keeps NaN and infinity, which
/// VTK's ASCII parser does not read back. ASCII is for reading the file by eye.
enum class VtuEncoding { Base64, Ascii };

/// Writes the triangles of `cc` at `positions` (3 × V, µm) atomically, with the given point and
/// triangle fields plus, always, triangle data `wall` (wall index), `cell` (label of the wall's
/// cell, -1 none), `outer` (1 on the outer surface) and point data `fixed` (1 = clamped). Throws
/// std::invalid_argument before writing anything if a field's size does not match (naming the
/// field), a name is empty, repeated or one of the built-in ones, or `positions` has the wrong
/// size; std::runtime_error if writing fails.
void writeVtu(const std::string& path, const CellComplex& cc, const Points& positions,
              const std::vector<VtuField>& pointFields = {},
              const std::vector<VtuField>& cellFields = {},
              VtuEncoding encoding = VtuEncoding::Base64);
/// Same to a stream (not atomic).
void writeVtu(std::ostream& out, const CellComplex& cc, const Points& positions,
              const std::vector<VtuField>& pointFields = {},
              const std::vector<VtuField>& cellFields = {},
              VtuEncoding encoding = VtuEncoding::Base64);

}  // namespace tp
