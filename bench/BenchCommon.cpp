#include "BenchCommon.h"

#include <sys/resource.h>

#include <cmath>
#include <map>
#include <stdexcept>

#include "io/Paths.h"
#include "io/Ply.h"
#include "tissue/Refine.h"

namespace tp::bench {

Material defaultMaterial() {
  Material m;
  m.youngModulus = 100;
  m.poissonRatio = 0.49;
  m.thickness = 0.2;
  m.bending = BendingModel::Hinge;
  return m;
}

double cellSize(const CellComplex& cc) {
  double v = 0;
  for (double x : cellVolumes(cc, cc.rest)) v += x;
  return std::cbrt(v / cc.cellCount());
}

std::shared_ptr<const CellComplex> refinedMeristem(int level) {
  static std::map<int, std::shared_ptr<const CellComplex>> cache;
  auto it = cache.find(level);
  if (it != cache.end()) return it->second;
  auto base = std::make_shared<CellComplex>(readPly(defaultTissuePath()));
  std::shared_ptr<const CellComplex> out = base;
  if (level > 0) {
    // As the CLI does: the site on the turgid unrefined tissue, refined around its rest position.
    Setup s = prepare(base);
    const ProbePlacement& pl = s.indentation->placement();
    const Vec3 at = restPositionOf(*s.model, s.indentation->turgidState(), pl.site, pl.triangle);
    const double radius = std::max(3 * kProbeRadius, cellSize(*base));
    out = std::make_shared<CellComplex>(refineNear(*base, at, radius, level));
  }
  cache[level] = out;
  return out;
}

Setup prepare(std::shared_ptr<const CellComplex> cc, SolverOptions options,
              IndentationSettings settings) {
  Setup s;
  s.cc = cc;
  s.model = std::make_unique<Model>(cc, defaultMaterial());
  s.model->setUniformPressure(kPressure);
  settings.probeRadius = kProbeRadius;
  s.indentation = std::make_unique<Indentation>(*s.model, settings, options);
  const SolveReport rep = s.indentation->prepare();
  if (!s.indentation->prepared())
    throw std::runtime_error("benchmark set-up: " + s.indentation->lastMessage());
  (void)rep;
  return s;
}

double peakMemoryMB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;  // ru_maxrss is in kB on Linux
}

}  // namespace tp::bench
