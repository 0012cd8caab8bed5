// libFuzzer target: the centroid-table reader (CSV/TSV with a header) on arbitrary bytes, with
// the column specification taken from the first line of the input so that positions and names
// are fuzzed too. Small accepted tables are also turned into a tissue (voro++ and CGAL), which
// is where degenerate centroids (coplanar, collinear, coincident) once went wrong.
// A refusal must be std::runtime_error or std::invalid_argument (the documented contracts);
// anything else, a crash, a leak or undefined behaviour is a finding.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

#include "io/Centroids.h"
#include "tissue/RealTissue.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  tp::CentroidColumns columns;
  // "#cols SPEC\n" first selects the columns, as --columns does.
  if (text.rfind("#cols ", 0) == 0) {
    const auto eol = text.find('\n');
    const std::string spec = text.substr(6, eol == std::string::npos ? std::string::npos : eol - 6);
    text = eol == std::string::npos ? std::string() : text.substr(eol + 1);
    try {
      columns = tp::CentroidColumns::parse(spec);
    } catch (const std::invalid_argument&) {
      return 0;
    } catch (const std::runtime_error&) {
      return 0;
    }
  }
  std::istringstream in(text);
  try {
    const tp::CentroidTable table = tp::readCentroids(in, "fuzz.csv", columns);
    if (table.points.size() != table.labels.size()) __builtin_trap();
    if (table.points.size() <= 12) {
      tp::RealTissueOptions options;
      (void)tp::tissueFromCentroids(table, options);
    }
  } catch (const std::invalid_argument&) {
  } catch (const std::runtime_error&) {
  }
  return 0;
}
