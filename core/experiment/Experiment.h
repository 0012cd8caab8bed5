#pragma once
// The indentation workflow, written once for every front end (tissueprobe-cli, the application,
// the benchmarks): the tissue at rest under its turgor pressure, the site chosen on it, the mesh
// refined around the site level by level (graded, tissue/Refine.h), the rest state and first
// contact on that mesh, the curve, and its discretisation error estimated from the next finer
// level of the same family, or from the coarser one the automatic mesh ran before (the grid
// convergence index of Roache 1994 with an assumed order).
// Units: µm, MPa, µN.

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "experiment/Indentation.h"
#include "mechanics/Model.h"
#include "solver/Solver.h"
#include "tissue/Refine.h"

namespace tp {

/// How the mesh at the site is chosen. Level 0 is the tissue as given; level L ≥ 1 refines it
/// around the site (siteRefinement()).
/// The largest mesh solved (vertices): ~750k unknowns, 7 GB peak on the scaling benchmark.
inline constexpr int kMaxVertices = 250000;

struct MeshSettings {
  bool automatic = true;      // refine level by level until the estimated error ≤ tolerance
  int level = 3;              // the fixed level; when automatic, the first level tried
  double tolerance = 0.03;    // relative error of the end value (see Experiment::endValue)
  bool estimateError = true;  // estimate the error of a fixed level too (costs a finer run)
  int maxLevel = 6;
  double grading = 1.5;       // the target edge grows by 1/grading per µm away from the site
  // Refine a band along the junctions of the walls around the site to the width of the bending
  // layer under turgor (siteRefinement, junctionLayerWidth). Off by default: it makes Koiter's
  // level-to-level differences shrink regularly, but costs ~3.5× per level and is not yet the
  // family the default's error estimate is checked on (bench/README.md, sixteenth session).
  bool junctionBand = false;
  // An unseeded refined rest state under turgor starts with the vertices the refinement added
  // relaxed, the tissue's own held (Experiment::relaxAddedVertices).
  bool relaxAddedVertices = true;
  // The longest edge anywhere on the walls of the refined zone at level 3, in cell sizes (halved
  // every level; siteRefinement). kStressPanelCells makes every wall there bulge under turgor
  // like the walls by the site, so that its stress shows no speckle; maps and sweeps, which
  // report forces only, use kForcePanelCells (mapSettings, Map.h): on the default meristem's 174
  // cell middles their forces are 0.27 % (sd; 0.14 % where the level is the same) from the
  // stress family's and the map takes 0.75 × the time (bench/README.md, nineteenth session).
  static constexpr double kStressPanelCells = 0.35;
  static constexpr double kForcePanelCells = 0.7;
  double panelCells = kStressPanelCells;
};

/// The graded refinement of level L ≥ 1 around a material point of the rest surface: longest
/// edges of R·2^(1−L) (R the probe radius) within R of it (the contact patch up to depths of
/// R/2), growing by 2^(3−L)/grading per µm beyond, on the whole of every wall reaching within
/// one cell size (at least 4 R) of that radius, whose edges are also at most `panelCells` cell
/// sizes × 2^(3−L) and, from level 3, 2^(2−L) times the longest edge they have in the tissue; and
/// (when junctionLayer > 0) at most 2·junctionLayer·2^(3−L) in a band of that width along
/// those of their junctions that come within R + 0.6 cell sizes of the point. Each level
/// halves the target size everywhere in that zone; the walls beyond keep the tissue's own
/// triangles.
GradedRefinement siteRefinement(const Vec3& restSite, double probeRadius, double cellSize,
                                int level, double grading, double junctionLayer = 0,
                                double panelCells = MeshSettings::kStressPanelCells);

/// The width ℓ = √(D/N) (µm) of the boundary layer in which a wall under turgor bends next to a
/// junction, N = p·cellSize/4 the tension of a turgid cell of that diameter; 0 without turgor or
/// bending. siteRefinement's band along the junctions is a multiple of it.
double junctionLayerWidth(const Material& material, double pressure, double cellSize);

struct ExperimentSettings;
/// Whether the refinement has the junction band: asked for (MeshSettings::junctionBand) and the
/// walls have a bending layer to resolve (turgor and bending; junctionLayerWidth).
bool junctionBandApplies(const ExperimentSettings& settings);

/// The clamped material of the outer surface (a clamped vertex, or an edge between two) within
/// `radius` (µm) of `point`, named for a message ("clamped vertex 295"), or empty if there is
/// none: a probe whose contact patch reaches it pushes on walls that cannot move.
std::string clampedMaterialWithin(const CellComplex& cc, const Vec3& point, double radius);

struct ExperimentSettings {
  Material material;
  double pressure = 0.8;            // MPa, every cell
  IndentationSettings indentation;  // probe, site, axis, schedule
  MeshSettings mesh;
  SolverOptions solver;

  /// Throws std::invalid_argument naming the first value out of its range, and the range.
  void validate() const;
};

/// The estimated discretisation error of an end value at one level, from the next finer level
/// or (the automatic mesh past its first level) from the coarser one.
struct MeshError {
  std::vector<std::pair<int, double>> values;  // (level, end value): the level, then the other
  double order = 0;     // the order of convergence assumed
  double relative = -1; // estimated |error| / |value| at the level; < 0: not estimated
  std::string method;   // how it was estimated, for reports
  bool estimated() const { return relative >= 0; }
  int level() const { return values.empty() ? -1 : values.front().first; }
  double value() const { return values.empty() ? 0.0 : values.front().second; }
};

/// The error of `value` at `level` from the end value at the next finer level. Levels halve the
/// mesh near the site, and the hinge bending model converges at about first order on graded
/// meshes (p ≈ 1.2 measured, tests/experiment), so first order is assumed: the remaining error
/// is at most 2 |F_L − F_{L+1}|, reported with Roache's safety factor 1.25 (Roache 1994, the
/// grid convergence index with p = 1), a bound while each difference is at most 0.6 of the
/// one before. Koiter bending (the default) in a tissue does not keep to that everywhere: from
/// level 4 to 6 its differences were 0.72–0.84 of the one before at two meristem sites
/// (bench/README.md, fifteenth session of 2026-12-06); level 3's estimates still covered
/// level 6 there. The cause is the walls' bending layer along the junctions under turgor, ~0.3
/// µm wide, which the family resolves only at level 6; with MeshSettings::junctionBand the
/// differences shrink by 0.57 or less from level 2 on (sixteenth session).
MeshError estimateMeshError(int level, double value, int finerLevel, double finerValue);

/// The error of `value` at `level` from the end value at the next coarser level, under the same
/// assumption: the differences at least halve level by level, so the error left at L is at most
/// Σ_{j≥1} 2^{−j} |F_{L−1} − F_L| = |F_{L−1} − F_L| (tight at first order, 1/(2^p − 1) of it at
/// order p), reported with the safety factor 1.25. The automatic mesh uses it once a level
/// coarser than the one it stops at has been run: both values are known by then, and no finer
/// level is solved for it.
MeshError estimateMeshErrorFromCoarser(int level, double value, int coarserLevel,
                                       double coarserValue);

/// A site prepared on one mesh level: the (refined) tissue, its model, its rest state under
/// turgor and the probe touching it.
struct PreparedSite {
  int level = 0;
  std::shared_ptr<const RefinedComplex> mesh;    // the tissue refined at the site, on its base
  std::shared_ptr<const CellComplex> complex;    // = mesh->complex
  RefineReport refinement;
  SolveReport rest;                          // the rest state's solve
  std::unique_ptr<Model> model;
  std::unique_ptr<Indentation> indentation;  // prepared; destroyed before the model
  double seconds = 0;                        // refinement + rest state + first contact
};

/// A solution on another mesh of the same tissue to start from: the mesh, its rest state under
/// turgor and (when `end` is not empty) its state at the schedule's end point, with the
/// probe's travel there. Carried over by transferPositions(), it saves most Newton iterations.
struct Seed {
  std::shared_ptr<const RefinedComplex> mesh;
  Points rest, end;
  double travel = 0;
};

/// Hears what the workflow does and may stop it.
struct Monitor {
  std::function<void(const std::string&)> stage;  // a stage begins ("Solving the rest state…")
  Indentation::PointCallback point;                // a point of the curve being run
  const std::atomic<bool>* cancel = nullptr;       // checked at every Newton iteration
  bool cancelled() const { return cancel && cancel->load(); }
  void say(const std::string& what) const {
    if (stage) stage(what);
  }
};

/// A solve the workflow needs did not converge (the message says which and why).
struct SolveFailure : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// The monitor's cancel flag was set.
struct Cancelled : std::runtime_error {
  Cancelled() : std::runtime_error("cancelled") {}
};

struct ExperimentResult {
  std::vector<CurvePoint> curve;         // from depth 0; ends early on failure or cancel
  bool complete = false;                 // every point of the schedule converged
  bool cancelled = false;
  MeshError error;                       // of the curve's end value
  bool withinTolerance = false;          // error.relative ≤ tolerance
  std::unique_ptr<PreparedSite> site;    // the mesh and the final state of the curve
  std::string message;                   // why the curve ended early, or a warning
};

class Experiment {
 public:
  /// `tissue` must be a valid complex with some clamped vertex (checked by prepareBase).
  Experiment(std::shared_ptr<const CellComplex> tissue, ExperimentSettings settings);
  ~Experiment();

  const ExperimentSettings& settings() const { return settings_; }
  /// New settings. The rest state is kept when material and pressure are unchanged; the site
  /// and the cached end values are recomputed when anything they depend on changed.
  void setSettings(ExperimentSettings settings);

  const std::shared_ptr<const CellComplex>& tissue() const { return tissue_; }
  double cellSize() const { return cellSize_; }

  /// The tissue as given at rest under its turgor pressure (solved once), and the site on it:
  /// the outer-surface point nearest to `indentation.site` (default: the top), remembered as a
  /// material point (`indentation.restSite` when given). Throws SolveFailure or Cancelled.
  void prepareBase(const Monitor& monitor = {});
  bool basePrepared() const { return baseReady_; }
  const Model& baseModel() const;
  const Points& baseRestState() const { return baseTurgid_; }
  const Vec3& restSite() const { return restSite_; }
  /// The probe's axis on every level: as asked, or the inward normal of the tissue as given.
  const Vec3& axis() const { return axis_; }
  const SolveReport& baseReport() const { return baseReport_; }

  /// The site prepared on the mesh of `level`: refinement, rest state (from the base's, carried
  /// onto the new vertices), first contact. Throws SolveFailure or Cancelled. With a spare core
  /// (setSpareCore) the refined model and its symbolic analysis are built on a thread of their
  /// own while the added vertices are relaxed (on one thread); the results are the same.
  std::unique_ptr<PreparedSite> prepareSite(int level, const Monitor& monitor = {},
                                            const Seed* seed = nullptr);

  /// The end point of the schedule (the deepest depth, or the largest force) on a prepared
  /// site: straight there from the site's rest state plus the seed's dimple (its end state
  /// less its rest state) carried onto this mesh, when the seed has an end state; otherwise, or
  /// if that solve fails, in up to four steps of the schedule. The point is returned converged
  /// or not (the site's indentation says why); throws Cancelled.
  CurvePoint solveEndPoint(PreparedSite& site, const Monitor& monitor = {},
                           const Seed* seed = nullptr);

  /// The end value of the schedule at a level: the force at the deepest point (depth control)
  /// or the depth at the largest force (force control), from a short run (at most 4 steps),
  /// remembered per level. Throws SolveFailure or Cancelled.
  double endValue(int level, const Monitor& monitor = {}, const Seed* seed = nullptr);
  /// Records an end value found otherwise (from a full curve at that level).
  void rememberEndValue(int level, double value) { endValues_[level] = value; }
  /// The error of `value` at `level` from the end value of the next finer level (computed when
  /// not yet known). A finer level that fails leaves the error not estimated.
  MeshError estimateError(int level, double value, const Monitor& monitor = {},
                          const Seed* seed = nullptr);
  /// The error of a curve's end value at `level` as the mesh settings judge it: with the
  /// automatic mesh past its first level, or at it when coarserResolvesContact(), from the next
  /// coarser level's end value (known when an automatic search ran it, else solved here, seeded
  /// by `seed`) when that estimate is within the tolerance (estimateMeshErrorFromCoarser);
  /// otherwise from the next finer level (estimateError). What run(), the application's curve
  /// runs and a fit's check at its fitted values report.
  MeshError curveError(int level, double value, const Monitor& monitor = {},
                       const Seed* seed = nullptr);
  /// Whether level − 1 (≥ 1) is fine enough under the probe for the error of `level` to be
  /// judged from it: its triangles there at most 0.8 of the contact radius √(R d) at the end
  /// depth d (`value` under force control, else the deepest depth).
  bool coarserResolvesContact(int level, double value) const;

  /// Whether prepareSite() may take a second core. Default: when the calling thread's OpenMP
  /// team has more than one thread (a map's workers have one each, and every core busy); the
  /// application's worker, which leaves one core to the drawing, lends it to a pick.
  void setSpareCore(bool spare) { spareCore_ = spare; }

  /// While on, the site an error estimate solves (the next finer level) is kept, and a run()
  /// that reaches that level starts from it instead of refining and solving it again (run()
  /// turns it on for itself, and off with what it kept when it ends). Off by default: a kept
  /// site holds a finer mesh's model and factor.
  void setKeepEstimatedSite(bool keep) {
    keepEstimated_ = keep;
    if (!keep) estimated_.reset();
  }

  /// The whole workflow: the curve at the fixed level, or (automatic) at the first level whose
  /// estimated error is within tolerance (up to maxLevel), with its error (curveError). Failures
  /// of the curve are reported in the result; failures before it (rest state, preparation) throw.
  ExperimentResult run(const Monitor& monitor = {});

 private:
  void checkCancel(const Monitor& m) const;
  void checkAgainstTissue(const ExperimentSettings& s) const;  // throws std::invalid_argument
  // The refined tissue's added vertices relaxed with its own held, into guess (kept if that fails).
  void relaxAddedVertices(const PreparedSite& site, Points& guess, const Monitor& monitor) const;

  std::shared_ptr<const CellComplex> tissue_;
  ExperimentSettings settings_;
  double cellSize_ = 0;
  std::unique_ptr<Model> baseModel_;
  Points baseTurgid_;
  SolveReport baseReport_;
  bool baseReady_ = false;
  Vec3 restSite_ = Vec3::Zero();
  Vec3 axis_ = -Vec3::UnitZ();
  std::map<int, double> endValues_;
  // The site of the last end value computed for run()'s error estimate, kept so that the next
  // level of the automatic mesh starts from it instead of refining and solving it again.
  std::unique_ptr<PreparedSite> estimated_;
  bool keepEstimated_ = false;
  std::optional<bool> spareCore_;
  std::shared_ptr<const RefinedComplex> unrefined_;  // the tissue as a refinement of itself
};

}  // namespace tp
