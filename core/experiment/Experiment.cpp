#include "experiment/Experiment.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <numbers>
#include <sstream>

#include "mesh/CellComplex.h"
#include "solver/Newton.h"
#include "solver/OpenMpRegions.h"

namespace tp {

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void require(bool ok, const std::string& what, double value, const std::string& range) {
  if (!ok)
    throw std::invalid_argument(what + " must be " + range + " (got " + number(value) + ")");
}

bool sameMechanics(const ExperimentSettings& a, const ExperimentSettings& b) {
  const Material &m = a.material, &n = b.material;
  return m.youngModulus == n.youngModulus && m.poissonRatio == n.poissonRatio &&
         m.thickness == n.thickness && m.bending == n.bending && m.junctions == n.junctions &&
         a.pressure == b.pressure && a.solver.kind == b.solver.kind &&
         a.solver.tolerance == b.solver.tolerance;
}

bool sameSite(const IndentationSettings& a, const IndentationSettings& b) {
  return a.site == b.site && a.restSite == b.restSite && a.axis == b.axis &&
         a.probeRadius == b.probeRadius;  // the default axis is the normal over the probe
}

// What the end values depend on besides the mechanics and the site.
bool sameEndValues(const ExperimentSettings& a, const ExperimentSettings& b) {
  const IndentationSettings &s = a.indentation, &t = b.indentation;
  return s.probeRadius == t.probeRadius && s.axis == t.axis && s.control == t.control &&
         (s.control == Control::Force ? s.maxForce == t.maxForce : s.maxDepth == t.maxDepth) &&
         a.mesh.grading == b.mesh.grading && a.mesh.junctionBand == b.mesh.junctionBand &&
         a.mesh.panelCells == b.mesh.panelCells;
}

}  // namespace

std::string clampedMaterialWithin(const CellComplex& cc, const Vec3& point, double radius) {
  if (cc.fixed.empty()) return {};
  const Points& X = cc.rest;
  for (int tri = 0; tri < cc.triangleCount(); ++tri) {
    if (!cc.isOuterTriangle(tri)) continue;
    for (int k = 0; k < 3; ++k) {
      const int a = cc.triangles[tri][k], b = cc.triangles[tri][(k + 1) % 3];
      if (!cc.fixed[a]) continue;
      if ((X.col(a) - point).norm() < radius) return "clamped vertex " + std::to_string(a);
      if (!cc.fixed[b]) continue;
      const Vec3 e = X.col(b) - X.col(a);
      const double u =
          std::clamp((point - X.col(a)).dot(e) / std::max(e.squaredNorm(), 1e-300), 0.0, 1.0);
      if ((X.col(a) + u * e - point).norm() < radius)
        return "the clamped edge " + std::to_string(a) + "-" + std::to_string(b);
    }
  }
  return {};
}

double junctionLayerWidth(const Material& material, double pressure, double cellSize) {
  if (material.bending == BendingModel::None || !(pressure > 0) || !(cellSize > 0)) return 0;
  // Units: µm, MPa, µN. A wall under tension N bends only within ℓ = √(D/N) of where its
  // curvature is constrained (the plate-under-tension equation D∇⁴w − N∇²w = p decays as
  // exp(−x/ℓ); Timoshenko & Woinowsky-Krieger, Theory of Plates and Shells, §3.7). N from
  // Laplace's law for a cell of diameter `cellSize`: N = p·(cellSize/2)/2.
  const double tension = pressure * cellSize / 4.0;
  return std::sqrt(material.bendingRigidity() / tension);
}

bool junctionBandApplies(const ExperimentSettings& s) {
  return s.mesh.junctionBand && junctionLayerWidth(s.material, s.pressure, 1.0) > 0;
}

GradedRefinement siteRefinement(const Vec3& restSite, double probeRadius, double cellSize,
                                int level, double grading, double junctionLayer,
                                double panelCells) {
  if (level < 1) throw std::invalid_argument("siteRefinement: level must be at least 1");
  GradedRefinement g;
  g.center = restSite;
  // Each level halves the target size everywhere in the zone: the finest size, and the growth
  // away from the site (grading × 2 per level, `grading` itself at level 3).
  g.finest = probeRadius * std::pow(2.0, 1 - level);
  g.grading = grading * std::pow(2.0, level - 3);
  g.innerRadius = probeRadius;  // the contact patch is within R up to depths of R/2
  g.outerRadius = g.innerRadius + std::max(cellSize, 4.0 * probeRadius);
  // Every wall of the zone fine enough to bulge under turgor like the walls by the site (a wall
  // left with its few flat triangles keeps the stress of an unrefined wall: a speckle). At 0.5
  // cell sizes one outer wall next to the default site kept a mean von Mises stress 23 % below
  // the uniformly refined one (RefinedPatchHasNoStressSpeckleUniformRefinementLacks); 0.35 keeps
  // every wall within 10 % (MeshSettings::kStressPanelCells), for ~20 % more vertices at level 3.
  g.panelSize = panelCells * cellSize * std::pow(2.0, 3 - level);
  // And from level 3 on, every level halves the longest edge of the zone's walls (half the base's
  // at level 3), so that two levels differ over the whole zone and the error estimated from them
  // (estimateMeshError) sees the walls away from the site too. Voronoi tissues' walls are cut
  // into triangles about a cell across, so the cap above is the finer one there and this changes
  // nothing; it refines tissues given on fine uniform meshes (a plate or a cap of a sphere, whose
  // whole surface bends under the probe), where the cap above left the zone as given at every
  // level and the estimate saw only the walls by the site (a clamped plate of 12 rings: 3.9 %
  // below the closed form with 2.75 % estimated).
  if (level >= 3) g.panelFraction = std::pow(2.0, 2 - level);
  // And a band along the junctions of the zone's walls, where under turgor each wall's bending
  // is confined to a boundary layer ℓ wide (junctionLayerWidth): edges of 2ℓ at level 3, halved
  // every level. Without it the layer was resolved only once the panels reached ℓ (level 6 of
  // the default meristem), and under Koiter bending each level's force change shrank by only
  // 0.72–0.84 from level 4 to 6 where the error estimate assumes halving; with it, at the same
  // two sites, by 0.57 and 0.35, 0.25 (bench/README.md, sixteenth session). Edges of √2·ℓ
  // converged a little more regularly (0.43, 0.31) for 25 % more time per level; edges of 4ℓ
  // left the box of cubic cells' mesh as it was and a meristem site at 0.55, 0.55.
  // The band follows only the junctions within 0.6 cell sizes of the contact patch: those of the
  // probed cell, whose walls the probe bends and unloads. On the default meristem (5 µm from
  // the site) that keeps 92 % of the whole zone's band's change of level 3's force with 8,457
  // vertices instead of 12,721, and the same ratios (0.56, 0.36 and 0.25, 0.42 at the two sites);
  // 0.45 cell sizes kept 64 % (bench/README.md, seventeenth session).
  if (junctionLayer > 0) {
    g.junctionSize = 2.0 * junctionLayer * std::pow(2.0, 3 - level);
    g.junctionRadius = g.innerRadius + 0.6 * cellSize;
  }
  return g;
}

void ExperimentSettings::validate() const {
  material.validate();
  require(material.youngModulus <= 1e6, "Young's modulus", material.youngModulus,
          "at most 1e6 MPa");
  require(material.thickness <= 100, "the wall thickness", material.thickness, "at most 100 µm");
  require(std::isfinite(pressure) && pressure >= 0 && pressure <= 100, "the turgor pressure",
          pressure, "between 0 and 100 MPa");
  const IndentationSettings& s = indentation;
  require(std::isfinite(s.probeRadius) && s.probeRadius >= 1e-3 && s.probeRadius <= 1e3,
          "the probe radius", s.probeRadius, "between 0.001 and 1000 µm");
  require(s.steps >= 1 && s.steps <= 100000, "the number of steps", s.steps,
          "between 1 and 100000");
  if (s.control == Control::Depth)
    require(std::isfinite(s.maxDepth) && s.maxDepth > 0 && s.maxDepth <= 1e3, "the depth",
            s.maxDepth, "positive and at most 1000 µm");
  else
    require(std::isfinite(s.maxForce) && s.maxForce > 0 && s.maxForce <= 1e7, "the force",
            s.maxForce, "positive and at most 1e7 µN");
  for (const auto* p : {&s.site, &s.restSite})
    if (*p && !(*p)->allFinite()) throw std::invalid_argument("the site must be finite");
  if (s.axis && !(s.axis->allFinite() && s.axis->norm() > 0))
    throw std::invalid_argument("the probe axis must be a finite, non-zero vector");
  require(mesh.level >= 0 && mesh.level <= mesh.maxLevel, "the refinement level", mesh.level,
          "between 0 and " + std::to_string(mesh.maxLevel));
  require(mesh.maxLevel >= 0 && mesh.maxLevel <= 12, "the largest refinement level",
          mesh.maxLevel, "between 0 and 12");
  require(std::isfinite(mesh.tolerance) && mesh.tolerance > 0 && mesh.tolerance <= 1,
          "the mesh tolerance", mesh.tolerance, "in (0, 1]");
  require(std::isfinite(mesh.grading) && mesh.grading >= 0.1 && mesh.grading <= 20,
          "the mesh grading", mesh.grading, "between 0.1 and 20");
  require(std::isfinite(mesh.panelCells) && mesh.panelCells >= 0.05 && mesh.panelCells <= 10,
          "the zone's panel size", mesh.panelCells, "between 0.05 and 10 cell sizes");
  require(std::isfinite(solver.tolerance) && solver.tolerance >= 1e-14 && solver.tolerance <= 1e-3,
          "the solver tolerance", solver.tolerance, "between 1e-14 and 1e-3");
}

namespace {

// The error of `value` at `level` from the end value at level `other`: `multiple` × their
// difference (first order assumed), with Roache's safety factor 1.25.
MeshError errorFromPair(int level, double value, int other, double otherValue, double multiple) {
  MeshError e;
  e.values = {{level, value}, {other, otherValue}};
  const double scale = std::abs(value);
  const double diff = std::abs(value - otherValue);
  if (!(scale > 0) || !std::isfinite(diff)) {
    e.method = "not estimated (end value zero or not finite)";
    return e;
  }
  e.order = 1;
  e.relative = 1.25 * multiple * diff / scale;
  std::ostringstream how;
  how << "level " << level << " against level " << other << ": " << value << " and "
      << otherValue << ", first-order convergence assumed, safety factor 1.25";
  e.method = how.str();
  return e;
}

// The error of `value` at `level` left unestimated, saying why.
MeshError notEstimated(int level, double value, const std::string& why) {
  MeshError e;
  e.values = {{level, value}};
  e.method = "not estimated: " + why;
  return e;
}

}  // namespace

MeshError estimateMeshError(int level, double value, int finerLevel, double finerValue) {
  // First order assumed: F_L − F* = Σ_{k≥L} (F_k − F_{k+1}) ≤ |F_L − F_{L+1}| Σ 2^{−j} = 2 |Δ|.
  return errorFromPair(level, value, finerLevel, finerValue, 2.0);
}

MeshError estimateMeshErrorFromCoarser(int level, double value, int coarserLevel,
                                       double coarserValue) {
  // First order assumed: F_L − F* = Σ_{k≥L} (F_k − F_{k+1}) ≤ |F_{L−1} − F_L| Σ_{j≥1} 2^{−j}.
  return errorFromPair(level, value, coarserLevel, coarserValue, 1.0);
}

Experiment::Experiment(std::shared_ptr<const CellComplex> tissue, ExperimentSettings settings)
    : tissue_(std::move(tissue)), settings_(std::move(settings)) {
  if (!tissue_) throw std::invalid_argument("Experiment: no tissue");
  settings_.validate();
  cellSize_ = meanCellSize(*tissue_);
  if (!(cellSize_ > 0)) cellSize_ = 5.0;  // a sheet: refine within a few µm
  checkAgainstTissue(settings_);
}

void Experiment::checkAgainstTissue(const ExperimentSettings& s) const {
  // What only makes sense relative to this tissue's size: a probe no larger than the tissue, and
  // depths that stay within it (deeper, the probe would come out of the far side).
  const Points& X = tissue_->rest;
  const double size = X.cols() ? (X.rowwise().maxCoeff() - X.rowwise().minCoeff()).norm() : 0.0;
  const IndentationSettings& i = s.indentation;
  if (i.probeRadius > size) {
    std::ostringstream o;
    o << "the probe radius (" << i.probeRadius << " µm) is larger than the tissue (" << size
      << " µm across)";
    throw std::invalid_argument(o.str());
  }
  if (i.control == Control::Depth && i.maxDepth > 0.5 * size) {
    std::ostringstream o;
    o << "the depth " << i.maxDepth << " µm is more than half the size of the tissue (" << size
      << " µm across): at most " << 0.5 * size << " µm";
    throw std::invalid_argument(o.str());
  }
}

Experiment::~Experiment() = default;

void Experiment::setSettings(ExperimentSettings s) {
  s.validate();
  checkAgainstTissue(s);
  if (!sameMechanics(s, settings_)) {
    baseReady_ = false;
    baseModel_.reset();
    endValues_.clear();
  } else if (!sameSite(s.indentation, settings_.indentation)) {
    baseReady_ = false;  // the rest state is kept; the site is found again
    endValues_.clear();
  } else if (!sameEndValues(s, settings_)) {
    endValues_.clear();
  }
  settings_ = std::move(s);
}

const Model& Experiment::baseModel() const {
  if (!baseModel_) throw std::logic_error("Experiment: prepareBase() first");
  return *baseModel_;
}

void Experiment::checkCancel(const Monitor& m) const {
  if (m.cancelled()) throw Cancelled();
}

void Experiment::prepareBase(const Monitor& monitor) {
  if (baseReady_) return;
  checkCancel(monitor);
  if (!baseModel_) {
    std::ostringstream what;
    what << "Solving the rest state under turgor (p = " << settings_.pressure << " MPa)…";
    monitor.say(what.str());
    baseModel_ = std::make_unique<Model>(tissue_, settings_.material);
    baseModel_->setUniformPressure(settings_.pressure);
    IndentationSettings s = settings_.indentation;
    s.site.reset();
    s.restSite.reset();
    Indentation rest(*baseModel_, s, settings_.solver);
    rest.solver().setCancelFlag(monitor.cancel);
    baseReport_ = rest.prepare();
    if (!rest.prepared()) {
      baseModel_.reset();
      checkCancel(monitor);
      throw SolveFailure(rest.lastMessage());
    }
    baseTurgid_ = rest.turgidState();
  }
  // The site on the turgid tissue, as a material point of the rest surface.
  const IndentationSettings& s = settings_.indentation;
  const Points& x = baseTurgid_;
  int t = -1;
  Vec3 site;
  auto where = [](const Vec3& v) {
    std::ostringstream o;
    o << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
    return o.str();
  };
  // A site given by the user must be on (or within a cell of) the surface: farther away, the
  // nearest surface point is somewhere the user did not mean.
  auto near = [&](const Vec3& asked, const Vec3& onSurface) {
    const double d = (asked - onSurface).norm();
    if (d > cellSize_) {
      std::ostringstream o;
      o << "the site " << where(asked) << " µm is " << d << " µm from the tissue surface, "
        << "more than a cell (" << cellSize_ << " µm): give a point on or near the surface";
      throw std::invalid_argument(o.str());
    }
  };
  if (s.restSite) {
    restSite_ = nearestSurfacePoint(*baseModel_, tissue_->rest, *s.restSite, &t);
    near(*s.restSite, restSite_);
  } else if (s.site) {
    site = nearestSurfacePoint(*baseModel_, x, *s.site, &t);
    near(*s.site, site);
    restSite_ = restPositionOf(*baseModel_, x, site, t);
  } else {
    // The top of the tissue as given: one material point whatever E, ν, h and p are, so that a
    // curve made at some values and fitted from others (tissueprobe-cli indent, then fit, both
    // without --site) is indented at the same point of the tissue. (The top of each turgid state
    // moved with the parameters: a level-2 curve made at E 100, p 0.8 and fitted from 130, 0.6
    // came out E 107.4 ± 5.8, p 0.784.)
    restSite_ = topSurfacePoint(*baseModel_, tissue_->rest, &t);
  }
  // Not on the clamped base: a probe whose contact patch (the probe radius around the site)
  // reaches clamped material (a clamped vertex, or an edge between two) pushes on walls that
  // cannot move.
  if (const std::string what = clampedMaterialWithin(*tissue_, restSite_, s.probeRadius);
      !what.empty()) {
    std::ostringstream o;
    o << "the site " << where(restSite_) << " µm is on the clamped base of the tissue (" << what
      << " is within the probe radius, " << s.probeRadius << " µm)";
    throw std::invalid_argument(o.str());
  }
  // One axis for every level and every E, ν, h and p: the inward normal of the tissue as given
  // (or the one asked for), so that refining, which lets the walls near the site bulge, does
  // not tilt the probe, and a curve fitted from other values than it was made at is indented
  // along the same line (the turgid state's normal at the starting values left a fit of a
  // level-2 curve made at E 100, p 0.8 at E 98.95 ± 1.62 from 130, 0.6).
  const Vec3 inward = inwardNormal(*baseModel_, tissue_->rest, restSite_, t, s.probeRadius);
  if (s.axis) {
    axis_ = s.axis->normalized();
    // Into the tissue: within 80° of the inward normal (a probe grazing the surface or pointing
    // out of it starts inside the tissue or never touches it).
    const double c = axis_.dot(inward);
    if (!(c > std::cos(80.0 * std::numbers::pi / 180.0))) {
      std::ostringstream o;
      o << "the probe axis " << where(*s.axis) << " does not point into the tissue at the site: it is "
        << std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / std::numbers::pi
        << "° from the inward normal " << where(inward) << " (at most 80° allowed)";
      throw std::invalid_argument(o.str());
    }
  } else {
    axis_ = inward;
  }
  baseReady_ = true;
}

std::unique_ptr<PreparedSite> Experiment::prepareSite(int level, const Monitor& monitor,
                                                      const Seed* seed) {
  prepareBase(monitor);
  checkCancel(monitor);
  const auto start = Clock::now();
  auto site = std::make_unique<PreparedSite>();
  site->level = level;
  const IndentationSettings& ind = settings_.indentation;
  if (level > 0) {
    std::ostringstream what;
    what << "Refining the mesh around the site (level " << level << ")…";
    monitor.say(what.str());
    const GradedRefinement spec =
        siteRefinement(restSite_, ind.probeRadius, cellSize_, level, settings_.mesh.grading,
                       settings_.mesh.junctionBand
                           ? junctionLayerWidth(settings_.material, settings_.pressure, cellSize_)
                           : 0.0,
                       settings_.mesh.panelCells);
    site->mesh = std::make_shared<const RefinedComplex>(refineGraded(*tissue_, spec));
  } else {
    if (!unrefined_) unrefined_ = std::make_shared<const RefinedComplex>(unrefined(*tissue_));
    site->mesh = unrefined_;
  }
  if (site->mesh->complex.vertexCount() > kMaxVertices) {
    std::ostringstream o;
    o << "mesh level " << level << " makes " << site->mesh->complex.vertexCount()
      << " vertices here, more than the " << kMaxVertices
      << " this program solves (about 7 GB on the scaling benchmark): choose a lower level or a "
         "looser --mesh-tolerance";
    throw std::invalid_argument(o.str());
  }
  site->complex = std::shared_ptr<const CellComplex>(site->mesh, &site->mesh->complex);
  site->refinement = site->mesh->report;
  // The rest state from a finer start than rest: the seed's, or the tissue's as given, carried
  // onto the new vertices.
  Points guess =
      seed && seed->mesh ? transferPositions(*tissue_, *seed->mesh, seed->rest, *site->mesh)
                         : prolongate(baseTurgid_, site->mesh->parents);
  monitor.say("Solving the rest state of the refined tissue…");
  // The refined tissue's model and its solver's symbolic analysis depend on the mesh alone.
  const auto build = [&] {
    site->model = std::make_unique<Model>(site->complex, settings_.material);
    site->model->setUniformPressure(settings_.pressure);
    IndentationSettings s = ind;
    s.site.reset();
    s.restSite = restSite_;
    s.axis = axis_;
    site->indentation = std::make_unique<Indentation>(*site->model, s, settings_.solver);
    site->indentation->solver().analyze();
  };
  if (level > 0 && !(seed && seed->mesh) && settings_.pressure != 0 &&
      settings_.mesh.relaxAddedVertices) {
    // With a core to spare they are made on a thread of their own while the added vertices are
    // relaxed on the other core, as one thread and BLAS on one thread (OpenBLAS's second thread
    // would spin on the core the analysis has): the default meristem's pick 0.95–0.99 →
    // 0.74–0.79 s, the real flower's 2.50–2.55 → 2.28–2.38 s (BM_PickSite*, bench/README.md).
    // The analyses still run one at a time (CholmodSolver::analyze). A map's workers, at one
    // thread each, have no core to spare and keep the order (setSpareCore).
    const int threads = omp_get_max_threads();
    if (spareCore_.value_or(threads > 1)) {
      auto built = std::async(std::launch::async, build);
      const OmpThreadsScope oneThread(1);
      const CholmodSolver::BlasThreadCap oneBlasThread(1);
      relaxAddedVertices(*site, guess, monitor);
      built.get();
    } else {
      relaxAddedVertices(*site, guess, monitor);
      build();
    }
  } else {
    build();
  }
  site->indentation->solver().setCancelFlag(monitor.cancel);
  site->rest = site->indentation->prepare(&guess);
  site->indentation->solver().setCancelFlag(nullptr);
  if (!site->indentation->prepared()) {
    checkCancel(monitor);
    throw SolveFailure("level " + std::to_string(level) + ": " +
                       site->indentation->lastMessage());
  }
  site->seconds = since(start);
  return site;
}

// The vertices the refinement added are relaxed first, with the tissue's own vertices held where
// its rest state put them: a smaller problem whose first tangents are the indefinite ones (new
// vertices flat under pressure), then the whole tissue from there. On the real flower (1,308
// cells, ~11,000 vertices at level 3) a pick took 3.2–3.3 s with the whole tissue's solve alone
// (5.3 iterations, 6 factorisations of ~30k unknowns), 2.7 s with this first (0.4 s of it,
// then 4 iterations); on the default meristem 0.9 → 1.05 s (bench/README.md, 2026-12-05).
// If it fails, the carried start is kept. A seeded start (another level's rest state carried
// over) is not relaxed this way: for the automatic mesh's finer level it cost more than it saved
// (`tissueprobe-cli indent --depth 0.5 --steps 10`: 9.8 s against 8.6–9.1 s).
void Experiment::relaxAddedVertices(const PreparedSite& site, Points& guess,
                                    const Monitor& monitor) const {
  auto held = std::make_shared<CellComplex>(site.mesh->complex);
  const int baseVertices = std::min(tissue_->vertexCount(), held->vertexCount());
  for (int v = 0; v < baseVertices; ++v) held->fixed[v] = 1;  // added vertices come after
  Model local(held, settings_.material);
  local.setUniformPressure(settings_.pressure);
  StaticSolver solver(local, settings_.solver);
  solver.setCancelFlag(monitor.cancel);
  Points x = guess;
  if (solver.solve(x).converged) guess = x;
}

CurvePoint Experiment::solveEndPoint(PreparedSite& site, const Monitor& monitor,
                                     const Seed* seed) {
  Indentation& ind = *site.indentation;
  const IndentationSettings& s = ind.settings();
  const bool force = s.control == Control::Force;
  const double top = force ? s.maxForce : s.maxDepth;
  ind.solver().setCancelFlag(monitor.cancel);
  CurvePoint pt;
  if (seed && seed->mesh && seed->end.cols() == seed->mesh->complex.vertexCount()) {
    // Straight to the end point: this level's rest state plus the seed's displacement from
    // its own rest state there (its dimple), carried over.
    const Points dimple = transferPositions(*tissue_, *seed->mesh, seed->end - seed->rest,
                                            *site.mesh);
    pt = ind.solveFrom(top, force, ind.turgidState() + dimple, seed->travel);
  }
  if (!pt.converged) {  // no seed, or a seed too far off: step there
    const int steps = std::min(s.steps, 4);
    for (int k = 1; k <= steps; ++k) {
      pt = force ? ind.applyForce(top * k / steps) : ind.goToDepth(top * k / steps);
      if (!pt.converged) break;
    }
  }
  ind.solver().setCancelFlag(nullptr);
  checkCancel(monitor);
  return pt;
}

double Experiment::endValue(int level, const Monitor& monitor, const Seed* seed) {
  const auto known = endValues_.find(level);
  if (known != endValues_.end()) {
    if (!std::isfinite(known->second))
      throw SolveFailure("level " + std::to_string(level) + " failed before");
    return known->second;
  }
  auto site = prepareSite(level, monitor, seed);
  std::ostringstream what;
  what << "Estimating the mesh error: level " << level << "…";
  monitor.say(what.str());
  const CurvePoint pt = solveEndPoint(*site, monitor, seed);
  if (!pt.converged)
    throw SolveFailure("level " + std::to_string(level) + " (mesh error estimate): " +
                       site->indentation->lastMessage());
  const bool force = site->indentation->settings().control == Control::Force;
  const double value = force ? pt.depth : pt.force;
  endValues_[level] = value;
  if (keepEstimated_) estimated_ = std::move(site);
  return value;
}

MeshError Experiment::estimateError(int level, double value, const Monitor& monitor,
                                    const Seed* seed) {
  endValues_[level] = value;
  try {
    return estimateMeshError(level, value, level + 1, endValue(level + 1, monitor, seed));
  } catch (const SolveFailure& e) {
    return notEstimated(level, value, e.what());
  }
}

bool Experiment::coarserResolvesContact(int level, double value) const {
  // Two levels tell the error only once both are in the asymptotic range; under the probe that
  // takes the contact patch (radius √(R d) at depth d) spanned by more than a triangle of the
  // coarser level (longest edges R·2^(2−L) there). Measured at level 3 against 2, turgid, to
  // 0.5 µm: R = 1 µm (edges 0.71 of the contact radius) on 15 cell middles, |F2 − F3| 1.7–3.2 %
  // against |F3 − F4| 0.86–1.23 %, and R = 0.25 µm (0.35) the error from levels 2, 3 covered the
  // true one; R = 3 µm (1.22) in the middle of a wall at the top, |F2 − F3| 0.8 % against
  // |F3 − F4| 3.9 %: level 2 is not yet converging there (ConvergedByDefault.TurgidLargeProbe).
  // A margin of 0.8: edges of at most 0.8 contact radii.
  if (level < 2) return false;
  const IndentationSettings& ind = settings_.indentation;
  const double depth = ind.control == Control::Force ? value : ind.maxDepth;
  if (!(depth > 0)) return false;
  const double edge = siteRefinement(restSite_, ind.probeRadius, cellSize_, level - 1,
                                     settings_.mesh.grading).finest;
  return edge <= 0.8 * std::sqrt(ind.probeRadius * depth);
}

MeshError Experiment::curveError(int level, double value, const Monitor& monitor,
                                 const Seed* seed) {
  endValues_[level] = value;
  const MeshSettings& mesh = settings_.mesh;
  if (mesh.automatic) {
    auto coarser = endValues_.find(level - 1);
    // The level before decides first: past the first level an automatic search has run it; at
    // the first level (and for a check of a finer mesh at new values, a fit's) it is solved
    // here, seeded — a coarser mesh, a fraction of the finer one's cost — if it is one of the
    // refined family and resolves the contact patch (coarserResolvesContact). If it fails or is
    // not within the tolerance, the finer level decides.
    const bool solveCoarser = level > mesh.level || coarserResolvesContact(level, value);
    if (coarser == endValues_.end() && solveCoarser) {
      const bool keep = keepEstimated_;
      keepEstimated_ = false;  // the site kept is the finer one's, for a search going on
      try {
        endValue(level - 1, monitor, seed);
      } catch (const SolveFailure&) {
      }
      keepEstimated_ = keep;
      coarser = endValues_.find(level - 1);
    }
    if (coarser != endValues_.end() && std::isfinite(coarser->second)) {
      MeshError e = estimateMeshErrorFromCoarser(level, value, level - 1, coarser->second);
      if (e.estimated() && e.relative <= mesh.tolerance) return e;
    }
  }
  return estimateError(level, value, monitor, seed);
}

ExperimentResult Experiment::run(const Monitor& monitor) {
  ExperimentResult result;
  const MeshSettings& mesh = settings_.mesh;
  const IndentationSettings& ind = settings_.indentation;
  const bool force = ind.control == Control::Force;
  Seed seed;  // the last level's solution, to start the next one from
  // The error estimate's site of level L + 1 becomes the next level's site (its rest state is
  // solved once, not twice); whatever is left is let go when the run ends.
  keepEstimated_ = true;
  struct Release {
    Experiment& e;
    ~Release() {
      e.keepEstimated_ = false;
      e.estimated_.reset();
    }
  } release{*this};
  for (int level = mesh.level;; ++level) {
    try {
      if (estimated_ && estimated_->level == level) {
        result.site = std::move(estimated_);
        result.site->indentation->returnToFirstContact();
        result.site->indentation->setSchedule(ind);
      } else {
        estimated_.reset();
        result.site = prepareSite(level, monitor, seed.mesh ? &seed : nullptr);
      }
    } catch (const Cancelled&) {
      if (!result.site) throw;  // nothing done yet
      // Stopped while refining further: the last level's complete curve stands, as it was.
      result.cancelled = true;
      result.message = "cancelled while preparing mesh level " + std::to_string(level) +
                       "; the curve of level " + std::to_string(level - 1) + " is kept";
      return result;
    }
    std::ostringstream what;
    what << "Running the curve (mesh level " << level << ")…";
    monitor.say(what.str());
    Indentation& indentation = *result.site->indentation;
    seed = Seed{};
    seed.mesh = result.site->mesh;
    seed.rest = indentation.turgidState();
    result.curve = indentation.run(
        [&](const CurvePoint& pt, int done, int total) {
          if (done == ind.steps) {  // the end point (before any unloading)
            seed.end = indentation.state();
            seed.travel = pt.depth;
          }
          if (monitor.point) monitor.point(pt, done, total);
        },
        monitor.cancel);
    result.cancelled = monitor.cancelled();
    const size_t expected = scheduleTargets(ind).size() + 1;
    result.complete = result.curve.size() == expected && result.curve.back().converged;
    if (!result.complete) {
      result.message = result.cancelled ? "cancelled" : indentation.lastMessage();
      return result;
    }
    const auto& end = result.curve[ind.steps];
    const double value = force ? end.depth : end.force;
    rememberEndValue(level, value);
    if (!mesh.automatic && !mesh.estimateError) return result;
    try {
      result.error = curveError(level, value, monitor, &seed);
    } catch (const Cancelled&) {
      result.cancelled = true;
      result.message = "cancelled while estimating the mesh error";
      return result;
    } catch (const std::invalid_argument& e) {  // the next level is larger than we solve
      result.error = notEstimated(level, value, e.what());
      result.message = std::string("the mesh error could not be estimated: ") + e.what();
      return result;
    }
    {
      std::ostringstream m;
      m << "Level " << level << ": end value " << value << ", estimated error "
        << 100 * result.error.relative << " % (" << result.error.method << ")";
      monitor.say(m.str());
    }
    result.withinTolerance =
        result.error.estimated() && result.error.relative <= mesh.tolerance;
    if (!mesh.automatic || result.withinTolerance) return result;
    if (level >= mesh.maxLevel) {
      std::ostringstream s;
      s << "the estimated mesh error " << 100 * result.error.relative << " % is above the "
        << 100 * mesh.tolerance << " % asked for at the finest level allowed (" << level << ")";
      result.message = s.str();
      return result;
    }
  }
}

}  // namespace tp
