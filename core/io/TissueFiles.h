#pragma once
// Tissue files: the formats TissueProbe reads a tissue from, chosen by the file's extension.
// A new format is its reader in its own file of core/io and one row in TissueFiles.cpp; the
// CLI, the application (its Open dialog's filter too) and the benchmarks read through
// readTissue. Units: µm.

#include <stdexcept>
#include <string>
#include <vector>

#include "io/Ply.h"
#include "mesh/CellComplex.h"

namespace tp {

/// What a read found besides the tissue (format, what was ignored, notes).
using TissueReadInfo = PlyInfo;

struct TissueFormat {
  const char* name;                     // "PLY (polygon file format)"
  std::vector<std::string> extensions;  // lower case, without the dot: {"ply"}
  CellComplex (*read)(const std::string& path, TissueReadInfo* info);
};

/// Every format, in the order a dialog lists them.
const std::vector<TissueFormat>& tissueFormats();

/// Reads the tissue in `path` with the reader of its extension (case-insensitive). Throws the
/// reader's error (naming the file and the line), or std::runtime_error naming the file and the
/// formats known when the extension is not one of them.
CellComplex readTissue(const std::string& path, TissueReadInfo* info = nullptr);

/// readTissue, then the checks every simulation makes: a valid complex (checkValidity) that
/// can be simulated (simulationProblem). Throws std::runtime_error naming the file and the
/// problem.
CellComplex readSimulationTissue(const std::string& path, TissueReadInfo* info = nullptr);

/// "Tissues (*.ply)" for file dialogs.
std::string tissueFileFilter();

}  // namespace tp
