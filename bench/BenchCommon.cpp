#include "BenchCommon.h"

#include <sys/resource.h>

#include <stdexcept>

#include "io/Paths.h"
#include "io/Ply.h"
#include "io/TissueFiles.h"

namespace tp::bench {

std::shared_ptr<const CellComplex> defaultMeristem() {
  static const auto cc = std::make_shared<const CellComplex>(readTissue(defaultTissuePath()));
  return cc;
}

ExperimentSettings defaultSettings(IndentationSettings schedule, SolverOptions solver) {
  ExperimentSettings s;  // the defaults of the CLI and the application
  s.indentation = schedule;
  s.solver = solver;
  return s;
}

Setup prepare(int level, ExperimentSettings settings, std::shared_ptr<const CellComplex> tissue) {
  Setup s;
  settings.mesh.automatic = false;
  settings.mesh.level = level;
  s.experiment = std::make_unique<Experiment>(std::move(tissue), settings);
  s.site = s.experiment->prepareSite(level);
  return s;
}

double peakMemoryMB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;  // ru_maxrss is in kB on Linux
}

}  // namespace tp::bench
