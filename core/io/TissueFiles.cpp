#include "io/TissueFiles.h"

#include <algorithm>
#include <cctype>

#include "mesh/Quality.h"

namespace tp {

namespace {

CellComplex readPlyFile(const std::string& path, TissueReadInfo* info) { return readPly(path, info); }

std::string lowerExtension(const std::string& path) {
  const auto slash = path.find_last_of("/\\");
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

const std::vector<TissueFormat>& tissueFormats() {
  static const std::vector<TissueFormat> formats{
      {"PLY (polygon file format; MorphoGraphX, openalea)", {"ply"}, readPlyFile},
  };
  return formats;
}

CellComplex readTissue(const std::string& path, TissueReadInfo* info) {
  const std::string ext = lowerExtension(path);
  std::string known;
  for (const auto& f : tissueFormats())
    for (const auto& e : f.extensions) {
      if (e == ext) return f.read(path, info);
      known += (known.empty() ? "." : ", .") + e;
    }
  throw std::runtime_error(path + ": not a tissue file TissueProbe reads (extension '" + ext +
                           "'; it reads " + known + ")");
}

std::string tissueFileFilter() {
  std::string patterns;
  for (const auto& f : tissueFormats())
    for (const auto& e : f.extensions) patterns += (patterns.empty() ? "*." : " *.") + e;
  return "Tissues (" + patterns + ")";
}

CellComplex readSimulationTissue(const std::string& path, TissueReadInfo* info) {
  CellComplex cc = readTissue(path, info);
  // simulationProblem checks validity first and says what an invalid file probably is.
  if (const std::string problem = simulationProblem(cc); !problem.empty())
    throw std::runtime_error(path + ": " + problem);
  return cc;
}

}  // namespace tp
