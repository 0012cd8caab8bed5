#pragma once
// Tables of cell centroids (µm), e.g. from a segmented confocal image: CSV or TSV with a header.

#include <istream>
#include <string>
#include <vector>

#include "mesh/CellComplex.h"

namespace tp {

/// Which columns hold the label and the coordinates: header names, or 1-based positions written
/// as numbers ("1", "2", ...). An empty label column numbers the rows 1, 2, ...
struct CentroidColumns {
  std::string label = "label", x = "x", y = "y", z = "z";
  std::string volume;  // optional column of measured volumes (µm³)
  /// Parses "label,x,y,z" or "label,x,y,z,volume" (names or positions).
  static CentroidColumns parse(const std::string& spec);
};

struct CentroidTable {
  std::vector<int> labels;
  std::vector<Vec3> points;      // µm
  std::vector<double> volumes;   // µm³, empty unless a volume column was read
};

/// Reads the table; the delimiter is a tab if the header has one, else a comma (or semicolon).
/// Quotes around fields are removed. Throws std::runtime_error naming the file, the line and the
/// column for a missing column, a value that is not a finite number, a repeated label, or fewer
/// than 4 rows.
CentroidTable readCentroids(const std::string& path, const CentroidColumns& columns = {});
/// The same from a stream; errors name `nameForErrors` in place of the file.
CentroidTable readCentroids(std::istream& in, const std::string& nameForErrors,
                            const CentroidColumns& columns = {});

}  // namespace tp
