#pragma once
// A measured force–indentation curve (an AFM experiment's, already converted to indentation and
// force) read from a table: CSV, TSV, semicolon- or whitespace-separated, `#` comment lines,
// an optional header row. The two columns are chosen by header name or 1-based position; their
// units are given or read from the header ("depth (nm)", "force_nN", "F [µN]"): m, µm (um), nm
// for lengths, N, µN (uN), nN, pN for forces. Values come out in µm and µN, in file order.

#include <string>
#include <vector>

namespace tp {

struct MeasuredCurve {
  std::string name;           // the file's name, for reports and legends
  std::vector<double> depth;  // µm
  std::vector<double> force;  // µN
};

struct MeasuredColumns {
  /// Header name (case-insensitive, with or without its unit) or 1-based position. Empty: the
  /// first column named depth/indentation/delta/separation (or the first column), and the first
  /// named force/F (or the second column).
  std::string depth, force;
  /// "nm", "um", "µm", "m"; "pN", "nN", "uN", "µN", "N". Empty: from the header, which must
  /// then say it.
  std::string depthUnit, forceUnit;
};

/// Parses table text. Throws std::runtime_error naming `nameForErrors`, and the line and value
/// for a bad number, a missing column or unit, fewer than two rows, non-finite values.
MeasuredCurve parseMeasuredCurve(const std::string& text, const std::string& nameForErrors,
                                 const MeasuredColumns& columns = {});
/// Reads the file (std::runtime_error if it cannot be opened).
MeasuredCurve readMeasuredCurve(const std::string& path, const MeasuredColumns& columns = {});

/// One unit in the program's units: µm per length unit ("nm" → 1e-3), µN per force unit
/// ("nN" → 1e-3); 0 for an unknown name.
double lengthUnitInMicrometres(const std::string& unit);
double forceUnitInMicronewtons(const std::string& unit);

}  // namespace tp
