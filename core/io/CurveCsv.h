#pragma once
// The force–indentation curve as CSV, one row per curve point:
//   depth_um,force_uN,iterations,residual,converged
// depth in µm, force in µN, converged as 0/1. Numbers are written in the shortest form that reads
// back exactly; NaN is written `nan` (infinities `inf`, `-inf`). Lines starting with `#` before
// the header are comments (what the curve is and its estimated discretisation error).

#include <string>
#include <string_view>
#include <vector>

#include "experiment/Indentation.h"

namespace tp {

/// The CSV text ("# " + each comment line, the header line, "\n" line ends).
std::string curveCsv(const std::vector<CurvePoint>& curve,
                     const std::vector<std::string>& comments = {});

/// Writes the CSV text atomically; throws std::runtime_error if writing fails.
void writeCurveCsv(const std::string& path, const std::vector<CurvePoint>& curve,
                   const std::vector<std::string>& comments = {});

/// Parses CSV text. Columns are found by their header names: the five above are required, an
/// optional `unloading` (0/1) column is read too (otherwise `unloading` is false), others are
/// ignored. Blank lines and `#` comment lines are skipped, "\r\n" line ends accepted. Throws std::runtime_error naming
/// `nameForErrors`, the line and the column.
std::vector<CurvePoint> parseCurveCsv(std::string_view text, const std::string& nameForErrors);

/// Reads a curve written by writeCurveCsv (or anything with the same columns).
std::vector<CurvePoint> readCurveCsv(const std::string& path);

}  // namespace tp
