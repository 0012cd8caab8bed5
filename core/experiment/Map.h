#pragma once
// Stiffness maps and parameter sweeps: the same indentation (Experiment, at its converged
// default mesh) at many sites of one tissue, and over a grid of parameter values, run by worker
// threads, in shards on a cluster, resumable. A run's folder holds
//   plan.json              what is computed: tissue, settings, sites, varied values (no timings)
//   results/task-NNNNNN.json  one finished task each, written atomically when it is done
//   map.csv                the table of every task in task order, once all are done
//   map.json               the plan and every task's result at full precision, likewise
//   map-surface.vtu        the outer surface coloured by the map (maps only), once all are done
//   run.log                timings and host names, appended by every run (never compared)
// A task is one (parameter set, site); tasks are numbered parameter set by parameter set, sites
// in plan order within each. Shard I of N runs the tasks with index ≡ I (mod N). The table and
// the surface depend on the plan and the results only, so a single run, a resumed run and the
// merge of shards write the same bytes. Units: µm, MPa, µN.

#include <array>
#include <atomic>
#include <limits>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "experiment/Experiment.h"
#include "mesh/CellComplex.h"

namespace tp {

enum class SiteKind { CellMiddle, Junction, Grid, Listed };
/// "cells", "junctions", "grid", "list".
std::string toString(SiteKind kind);
/// Throws std::invalid_argument naming the word and the choices.
SiteKind parseSiteKind(const std::string& word);

/// A site of a map, indented along the inward normal unless an axis is given: a generated site
/// (cells, junctions, grid) is a material point of the rest outer surface, indented where it is
/// in the turgid state; a listed site is a place, and the nearest turgid surface point to it is
/// indented.
struct MapSite {
  SiteKind kind = SiteKind::Listed;
  std::string label;           // "cell 12", "cells 3|17", "grid 2,-1", "line 4"
  Vec3 point = Vec3::Zero();   // µm
};

/// The middle of every cell's outer wall (of a cell's walls on the outer surface, the one with
/// the most free area; ties to the highest): the point of the wall nearest to its area-weighted
/// centre (clamped triangles left out). In cell order.
std::vector<MapSite> cellMiddleSites(const CellComplex& cc);
/// Every anticlinal junction on the surface: where the outer walls of two cells meet, the point
/// of their common edges nearest to the edges' length-weighted centre (edges with both ends
/// clamped left out). In order of the cell pair.
std::vector<MapSite> junctionSites(const CellComplex& cc);
/// A square grid of the given spacing (µm) over the tissue seen from above (+z), centred on the
/// free outer surface's bounding box: each grid point dropped vertically onto the highest
/// upward-facing free outer triangle below it (as an AFM raster). Row by row, x fastest.
std::vector<MapSite> gridSites(const CellComplex& cc, double spacing);
/// A list of sites: a CSV/TSV (or whitespace-separated) text of x,y,z in µm, one per line, an
/// optional header line, '#' comments. Throws std::runtime_error naming file, line and value.
std::vector<MapSite> readSiteList(const std::string& path);

/// The sites of several kinds, in the order given: `gridSpacing` (µm, NaN: the mean cell size)
/// for a grid, `siteList` (a file, see readSiteList) for a list, which must lie near the surface
/// (checkSitesNearSurface). Sites the program chose (cells, junctions, grid) whose contact patch
/// would reach the clamped base — clamped material within `probeRadius` (µm; NaN: none left
/// out), clampedMaterialWithin — are left out, into *leftOut if given: no probe can indent
/// them, and on a real tissue (the flower of ../shared/data) every map would otherwise end with
/// failed sites. Listed sites are the user's own and are kept (their tasks fail, saying why).
/// Throws std::invalid_argument naming the option ("--grid-spacing", "--site-list") and the
/// problem; std::runtime_error for a bad list file.
std::vector<MapSite> mapSites(const CellComplex& cc, const std::vector<SiteKind>& kinds,
                              double gridSpacing, const std::string& siteList,
                              double probeRadius = std::numeric_limits<double>::quiet_NaN(),
                              std::vector<MapSite>* leftOut = nullptr);

/// Throws std::invalid_argument naming `source`, the site's label and its distance when a site is
/// farther than the mean cell size from the free outer surface of the rest tissue.
void checkSitesNearSurface(const CellComplex& cc, const std::vector<MapSite>& sites,
                           const std::string& source);

/// A varied parameter of a sweep: name (E, nu, h, p, probe-radius) and its values.
struct Variation {
  std::string name;
  std::vector<double> values;
};
/// "E=50:200:4" (4 values from 50 to 200, evenly) or "p=0,0.4,0.8". Throws
/// std::invalid_argument naming the text and what is wrong.
Variation parseVariation(const std::string& text);
/// Sets the named parameter. Throws std::invalid_argument for an unknown name.
void applyVariation(ExperimentSettings& settings, const std::string& name, double value);

/// An indentation's settings as a map or a sweep runs them: the same, but a map reports forces
/// and draws no stress, so the walls of the zone refined at each site are in panels made for
/// forces (MeshSettings::kForcePanelCells) rather than for the stress picture.
ExperimentSettings mapSettings(ExperimentSettings indentation);

/// What a map or a sweep computes. Everything in it is in plan.json; two runs with the same
/// plan compute the same tasks.
struct MapPlan {
  std::string tissue;        // the tissue file, absolute
  std::string tissueDigest;  // counts and a hash of the rest geometry: the same tissue?
  ExperimentSettings settings;
  std::vector<Variation> vary;  // empty for a map
  std::vector<MapSite> sites;

  /// At most this many tasks (so that task numbers fit an int with room to spare).
  static constexpr double kMaxTasks = 1e8;
  /// Throws std::invalid_argument when sites × parameter sets exceeds kMaxTasks.
  void checkSize() const;
  int parameterSets() const;
  /// The largest probe radius of its tasks (µm): the settings' or a varied probe-radius's.
  double largestProbeRadius() const;
  int taskCount() const { return parameterSets() * static_cast<int>(sites.size()); }
  const MapSite& site(int task) const;
  std::vector<double> values(int task) const;   // the varied values of the task, in vary order
  ExperimentSettings taskSettings(int task) const;  // with the site (see MapSite) and values

  nlohmann::json toJson() const;
  /// Reads what the table and the surface need (tissue, digest, vary, sites); the settings
  /// stay as JSON (`settingsJson`). Throws std::runtime_error naming `file` and the key.
  static MapPlan fromJson(const nlohmann::json& j, const std::string& file);
  nlohmann::json settingsJson;  // as read (fromJson); when set, toJson writes it for `settings`
};

/// A digest of a tissue's counts and rest geometry ("V 1234, T 5678, C 512, fnv 0123abcd…").
std::string tissueDigest(const CellComplex& cc);

/// The outcome of one task.
struct TaskResult {
  int task = -1;
  Vec3 contact = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());  // µm, turgid site
  double depth = std::numeric_limits<double>::quiet_NaN();    // µm at the end point
  double force = std::numeric_limits<double>::quiet_NaN();    // µN at the end point
  double secant = std::numeric_limits<double>::quiet_NaN();   // µN/µm, F/δ at the end point
  double tangent = std::numeric_limits<double>::quiet_NaN();  // µN/µm, slope of the last step
  double hertz = std::numeric_limits<double>::quiet_NaN();    // MPa, Hertz apparent modulus
  int level = -1;                 // the mesh level of the curve
  double meshError = -1;          // relative estimated discretisation error; < 0 not estimated
  std::string status;             // "converged", "mesh error above tolerance", "failed"
  std::string message;            // why it failed, or a warning
  std::vector<std::array<double, 2>> curve;  // (depth µm, force µN) of the loading, from 0
  double seconds = 0;             // wall time (run log only, not in the table)

  bool converged() const { return status == "converged"; }
  nlohmann::json toJson() const;  // without the seconds
  /// Throws std::runtime_error naming `file` and the key.
  static TaskResult fromJson(const nlohmann::json& j, const std::string& file);
};

/// The result of one task from its experiment's result (the curve's end point).
TaskResult taskResult(int task, const ExperimentSettings& settings, const ExperimentResult& r);

/// A map's values over the surface, from its converged sites: at a point, the value of the
/// nearest site, or Shepard's inverse-distance interpolation (power 2, Shepard 1968) of the
/// sites within twice the median distance between neighbouring sites (at most `maxRadius`: a
/// map half done is not spread over the surface). A site is where its
/// generated point is (a material point of the rest surface) or, for a listed site, where it was
/// indented (its contact point). Units: µm, and those of the value.
class MapField {
 public:
  enum Value { Stiffness, Force, Hertz };  // secant µN/µm, µN, MPa
  static constexpr int kValueCount = 3;
  MapField(const MapPlan& plan, const std::vector<TaskResult>& results,
           double maxRadius = std::numeric_limits<double>::infinity());
  bool empty() const { return sites_.empty(); }
  int siteCount() const { return static_cast<int>(sites_.size()); }
  double radius() const { return radius_; }
  /// The task of the converged site nearest to x, or −1 without any.
  int nearestTask(const Vec3& x, double* distance = nullptr) const;
  double nearest(const Vec3& x, Value v) const;       // NaN without sites
  double interpolated(const Vec3& x, Value v) const;  // NaN beyond the radius of every site

 private:
  int nearestSite(const Vec3& x, double* distance = nullptr) const;  // index, −1 without sites
  struct Site {
    Vec3 x;
    int task;
    double value[kValueCount];
  };
  std::vector<Site> sites_;
  double radius_ = std::numeric_limits<double>::infinity();
};

/// The map's table: a header, then one row per task in task order.
std::string mapTable(const MapPlan& plan, const std::vector<TaskResult>& results);
/// The outer surface (rest geometry) coloured by the map: per triangle, the values of the
/// nearest converged site ("site_*"); per vertex, Shepard's inverse-distance interpolation of the
/// converged sites within twice the median distance between neighbouring sites
/// ("interpolated_*"). Fields: stiffness (secant, µN/µm), force (µN), hertz (MPa). Maps only.
std::string mapSurfaceVtu(const CellComplex& cc, const MapPlan& plan,
                          const std::vector<TaskResult>& results);

struct MapProgress {
  int done = 0;      // tasks finished in this run
  int failed = 0;    // of them, not converged
  int todo = 0;      // tasks this run set out to do
  int skipped = 0;   // of the shard's tasks, found done in the folder
  double seconds = 0;
  const TaskResult* last = nullptr;
};

struct MapRunOptions {
  std::string outDir;
  int jobs = 1;              // worker threads, each with its own experiment and solver
  int shard = 0, shards = 1;
  const std::atomic<bool>* cancel = nullptr;
  std::function<void(const MapProgress&)> progress;  // after each task, from a worker (serialised)
  std::string host;          // for the run log
};

struct MapRunSummary {
  int shardTasks = 0, skipped = 0, done = 0, failed = 0;
  bool cancelled = false;
  bool complete = false;     // every task of the plan has its result in the folder
  std::vector<std::string> written;  // the table and surface, when complete
};

/// Runs the shard's tasks not yet in `outDir` (creating it and plan.json; an existing plan.json
/// must be the same plan, else std::runtime_error says what differs). Each finished task is
/// written at once; a cancel stops the workers at their next Newton iteration and keeps what
/// is done. When every task of the plan is in the folder, writes map.csv (and map-surface.vtu).
MapRunSummary runMap(std::shared_ptr<const CellComplex> tissue, const MapPlan& plan,
                     const MapRunOptions& options);

struct MergeSummary {
  int tasks = 0, found = 0;
  std::vector<int> missing;  // task indices not in any folder
  std::vector<std::string> written;
};
/// Gathers the results of shard folders (their plan.json must be the same plan) into `outDir`
/// as a single run would have left it: plan.json, results/, map.csv, map-surface.vtu. The
/// tissue is read from the plan's path unless given. Nothing but results/ and run.log is written
/// when tasks are missing. Throws std::runtime_error naming the folder and the problem.
MergeSummary mergeMaps(const std::vector<std::string>& dirs, const std::string& outDir,
                       std::shared_ptr<const CellComplex> tissue = nullptr);

/// The results in a folder for a plan (task order; missing tasks have task = -1).
std::vector<TaskResult> readResults(const std::string& dir, const MapPlan& plan);

}  // namespace tp
