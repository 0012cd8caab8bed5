// tissueprobe-cli: command-line runs of the TissueProbe core.
//   indent  one indentation curve (CSV, VTU)
//   fit     wall modulus, turgor, thickness from measured curves (JSON report, CSV)
//   map     a stiffness map: the indentation at many sites (parallel, sharded, resumable)
//   sweep   the same over a grid of parameter values
//   merge   the shards of a map or sweep into one set of outputs
//   info    size, closedness and quality of a tissue file
//   build   make a tissue file
// Units everywhere: µm, MPa, µN.

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <thread>
#include <string>
#include <sched.h>
#include <unistd.h>

#include "experiment/Analysis.h"
#include "experiment/Experiment.h"
#include "experiment/Fit.h"
#include "experiment/Indentation.h"
#include "experiment/Map.h"
#include "experiment/Stress.h"
#include "io/AtomicFile.h"
#include "io/Centroids.h"
#include "io/CurveCsv.h"
#include "io/JpkCurve.h"
#include "io/MeasuredCurve.h"
#include "io/Paths.h"
#include "io/Ply.h"
#include "io/TextFile.h"
#include "io/TissueFiles.h"
#include "io/Vtu.h"
#include "mesh/Quality.h"
#include "solver/Memory.h"
#include "tissue/Meristem.h"
#include "tissue/RealTissue.h"
#include "tissue/Shapes.h"

namespace {

using namespace tp;

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Ctrl-C (SIGINT) or SIGTERM during a run: the first asks the solver to stop at its next Newton
// iteration and the points done are kept (printed and written); a second one stops at once.
// Exit status 130, as a shell reports an interrupted command.
constexpr int kExitInterrupted = 130;
// Exit status 4: an output could not be written (refused before any work when it is read-only or
// its folder is missing, or failed at the end; nothing is replaced either way).
constexpr int kExitCannotWrite = 4;
std::atomic<bool> interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free);  // set from a signal handler

extern "C" void onInterrupt(int sig) {
  interrupted.store(true);
  std::signal(sig, SIG_DFL);  // the next one ends the process
}

// Installs onInterrupt for the lifetime of the object, restoring the previous handlers after
// (so the atomic writer's own clean-up of temporary files takes over while outputs are written).
class InterruptScope {
 public:
  InterruptScope() {
    for (int i = 0; i < 2; ++i) {
      struct sigaction sa {};
      sa.sa_handler = onInterrupt;
      sigemptyset(&sa.sa_mask);
      sigaction(kSignals[i], &sa, &old_[i]);
    }
  }
  ~InterruptScope() {
    for (int i = 0; i < 2; ++i) sigaction(kSignals[i], &old_[i], nullptr);
  }
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;

 private:
  static constexpr int kSignals[2] = {SIGINT, SIGTERM};
  struct sigaction old_[2] {};
};

// Outputs are checked before any work: never an input (a --csv naming the tissue would replace
// it), never two outputs on one file, and each writable (an existing read-only file is kept).
void checkOutputs(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  auto same = [](const std::string& a, const std::string& b) {
    std::error_code ec;
    if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
    return fs::weakly_canonical(a, ec) == fs::weakly_canonical(b, ec);
  };
  for (size_t i = 0; i < outputs.size(); ++i) {
    if (outputs[i].empty()) continue;
    for (const auto& in : inputs)
      if (!in.empty() && same(outputs[i], in))
        throw UsageError("the output '" + outputs[i] + "' is the input file '" + in +
                         "': choose another name (it would be overwritten)");
    for (size_t j = 0; j < i; ++j)
      if (!outputs[j].empty() && same(outputs[i], outputs[j]))
        throw UsageError("two outputs are the same file: '" + outputs[j] + "' and '" +
                         outputs[i] + "'");
    checkWritable(outputs[i]);  // WriteError: exit 4, before any work
  }
}

Vec3 parseVec3(const std::string& text, const std::string& option) {
  std::stringstream ss(text);
  Vec3 v;
  std::string item;
  int k = 0;
  while (std::getline(ss, item, ',')) {
    if (k >= 3)
      throw UsageError(option + ": expected three comma-separated numbers, got '" + text + "'");
    try {
      size_t used = 0;
      v[k] = std::stod(item, &used);
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UsageError(option + ": '" + item + "' is not a number (expected x,y,z in µm)");
    }
    if (!std::isfinite(v[k])) throw UsageError(option + ": '" + item + "' is not finite");
    ++k;
  }
  if (k != 3 || ss.rdbuf()->in_avail() > 0)
    throw UsageError(option + ": expected three comma-separated numbers, got '" + text + "'");
  return v;
}

CellComplex loadTissue(const std::string& path) { return readSimulationTissue(path); }

struct IndentArgs {
  std::string mesh;
  // Defaults are core's, as in the application.
  double E = Material{}.youngModulus, nu = Material{}.poissonRatio, thickness = Material{}.thickness,
         pressure = ExperimentSettings{}.pressure;
  std::string bending = toString(Material{}.bending);
  std::string junctions = toString(Material{}.junctions);
  double probeRadius = IndentationSettings{}.probeRadius;
  std::string site, axis;
  std::optional<double> depth, force;
  int steps = IndentationSettings{}.steps;
  bool unload = false;
  bool noPredictor = false;
  std::string refine = "auto";
  double meshTolerance = MeshSettings{}.tolerance;
  bool junctionBand = MeshSettings{}.junctionBand;
  std::optional<double> meshPanels;  // the command's own default when not given
  std::string csv, vtu;
  double tolerance = 1e-8;
  std::string solver = "newton";
  bool verbose = false, quiet = false, progress = false;
};

std::string bendingLabel(const Material& m) {
  return m.bending == BendingModel::Koiter ? "koiter (" + toString(m.junctions) + " junctions)"
                                           : toString(m.bending);
}

ExperimentSettings experimentSettings(const IndentArgs& a) {
  ExperimentSettings x;
  x.material.youngModulus = a.E;
  x.material.poissonRatio = a.nu;
  x.material.thickness = a.thickness;
  x.material.bending = parseBendingModel(a.bending);
  x.material.junctions = parseJunctionRule(a.junctions);
  x.pressure = a.pressure;
  IndentationSettings& s = x.indentation;
  s.probeRadius = a.probeRadius;
  if (!a.site.empty()) s.site = parseVec3(a.site, "--site");
  if (!a.axis.empty()) s.axis = parseVec3(a.axis, "--axis");
  s.steps = a.steps;
  s.unload = a.unload;
  s.predictor = !a.noPredictor;
  if (a.force) {
    s.control = Control::Force;
    s.maxForce = *a.force;
  } else {
    s.maxDepth = a.depth.value_or(0.5);
  }
  if (a.refine == "auto") {
    x.mesh.automatic = true;
  } else {
    x.mesh.automatic = false;
    try {
      size_t used = 0;
      x.mesh.level = std::stoi(a.refine, &used);
      if (used != a.refine.size()) throw std::invalid_argument(a.refine);
    } catch (const std::exception&) {
      throw UsageError("--refine: expected auto or a level 0-" +
                       std::to_string(x.mesh.maxLevel) + ", got '" + a.refine + "'");
    }
  }
  x.mesh.tolerance = a.meshTolerance;
  x.mesh.junctionBand = a.junctionBand;
  if (a.meshPanels) x.mesh.panelCells = *a.meshPanels;
  x.solver.kind = parseSolverKind(a.solver);
  if (x.solver.kind == SolverKind::ImplicitEulerCG && a.force)
    throw UsageError("--solver implicit-euler-cg supports --depth only");
  if (x.solver.kind == SolverKind::ImplicitEulerCG && x.material.bending == BendingModel::Koiter)
    throw UsageError("--solver implicit-euler-cg runs the published bending models: add "
                     "--bending linear (as published), hinge or none");
  x.solver.tolerance = a.tolerance;
  x.solver.verbose = a.verbose;
  x.validate();
  return x;
}

/// "±1.2 % of the force at 0.5 um (grid convergence index of levels 1-3, ...)".
std::string describeError(const MeshError& e, const ExperimentSettings& s) {
  std::ostringstream out;
  const bool force = s.indentation.control == Control::Force;
  if (!e.estimated()) {
    out << "estimated discretisation error: "
        << (e.method.empty() ? "not estimated (the curve did not reach its end)" : e.method);
    return out.str();
  }
  out.precision(2);
  out << "estimated discretisation error +-" << std::fixed << 100 * e.relative << " % of the "
      << (force ? "depth at " : "force at ");
  out.unsetf(std::ios::fixed);
  out.precision(6);
  out << (force ? s.indentation.maxForce : s.indentation.maxDepth) << (force ? " uN" : " um")
      << " (" << e.method << ")";
  return out.str();
}

int runIndent(const IndentArgs& a) {
  if (a.depth && a.force) throw UsageError("give --depth or --force, not both");
  const std::string meshPath = a.mesh.empty() ? defaultTissuePath() : a.mesh;
  checkOutputs({a.csv, a.vtu}, {meshPath});
  const ExperimentSettings settings = experimentSettings(a);
  auto cc = std::make_shared<const CellComplex>(loadTissue(meshPath));
  Experiment experiment(cc, settings);
  const Material& mat = settings.material;
  if (!a.quiet) {
    std::printf("# tissue %s: %d cells, %d vertices, %d triangles\n", meshPath.c_str(),
                cc->cellCount(), cc->vertexCount(), cc->triangleCount());
    std::printf("# E = %g MPa, nu = %g, h = %g um, p = %g MPa, bending %s, probe radius %g um\n",
                mat.youngModulus, mat.poissonRatio, mat.thickness, settings.pressure,
                bendingLabel(mat).c_str(), settings.indentation.probeRadius);
  }
  Monitor monitor;
  monitor.cancel = &interrupted;
  const auto started = std::chrono::steady_clock::now();
  auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  };
  // On a terminal a progress line is rewritten in place at every point of the curve; with
  // --progress elsewhere (a log file, a pipe) one line per point is printed.
  const bool terminal = !a.quiet && ::isatty(STDERR_FILENO);
  const bool lines = !a.quiet && !terminal && a.progress;
  bool progressShown = false;
  auto endProgress = [&] {
    if (progressShown) std::fprintf(stderr, "\n");
    progressShown = false;
  };
  if (!a.quiet)
    monitor.stage = [&](const std::string& what) {
      endProgress();
      std::fprintf(stderr, "[%6.2f s] %s\n", seconds(), what.c_str());
    };
  if (terminal)
    monitor.point = [&](const CurvePoint& p, int done, int total) {
      std::fprintf(stderr, "\r\033[K[%6.2f s] point %d/%d: depth %.4f um, force %.6g uN%s", seconds(),
                   done, total, p.depth, p.force, p.converged ? "" : " (not converged)");
      std::fflush(stderr);
      progressShown = true;
    };
  else if (lines)
    monitor.point = [&](const CurvePoint& p, int done, int total) {
      std::fprintf(stderr, "[%6.2f s] point %d/%d: depth %.4f um, force %.6g uN%s\n", seconds(),
                   done, total, p.depth, p.force, p.converged ? "" : " (not converged)");
      std::fflush(stderr);
    };
  ExperimentResult r;
  {
    InterruptScope scope;
    try {
      r = experiment.run(monitor);
    } catch (const SolveFailure& e) {
      endProgress();
      std::fprintf(stderr, "error: %s\n", e.what());
      return 3;
    } catch (const Cancelled&) {
      endProgress();
      std::fprintf(stderr, "interrupted before the first point of the curve: nothing written\n");
      return kExitInterrupted;
    }
    endProgress();
  }
  const PreparedSite& site = *r.site;
  const Indentation& ind = *site.indentation;
  const ProbePlacement& pl = ind.placement();
  std::vector<std::string> comments;
  {
    std::ostringstream m;
    m << "mesh level " << site.level << (settings.mesh.automatic ? " (auto, tolerance " : " (fixed")
      << (settings.mesh.automatic ? std::to_string(settings.mesh.tolerance) + ")" : ")") << ": "
      << site.complex->vertexCount() << " vertices, " << site.complex->triangleCount()
      << " triangles, smallest angle " << site.refinement.minAngleDeg << " deg"
      << (junctionBandApplies(settings) ? ", junction band" : "");
    if (settings.mesh.panelCells != MeshSettings::kStressPanelCells)
      m << ", panels of " << settings.mesh.panelCells << " cell sizes at level 3";
    comments.push_back(m.str());
    comments.push_back(describeError(r.error, settings));
    std::ostringstream w;
    w << "site " << pl.site.x() << "," << pl.site.y() << "," << pl.site.z() << " um, axis "
      << pl.axis.x() << "," << pl.axis.y() << "," << pl.axis.z() << "; E " << mat.youngModulus
      << " MPa, nu " << mat.poissonRatio << ", h " << mat.thickness << " um, p "
      << settings.pressure << " MPa, bending " << bendingLabel(mat) << ", probe radius "
      << settings.indentation.probeRadius << " um";
    comments.push_back(w.str());
    if (r.cancelled)
      comments.push_back("interrupted by the user after " + std::to_string(r.curve.size()) +
                         " point(s): " + r.message);
  }
  if (!a.quiet) {
    // A rest state that needed no iteration is the tissue as given (without turgor: its
    // residual is round-off, and relative to a load scale of nothing but the solver's floor it
    // read as a poor convergence, 6e-03 at p = 0) or, on the tissue's own mesh, the turgid
    // state solved before the site was chosen.
    if (site.rest.converged && site.rest.iterations == 0)
      std::printf("# rest state: %s (residual %.2e uN)\n",
                  settings.pressure == 0 ? "in equilibrium as given"
                                         : "the turgid state of the tissue's own mesh",
                  site.rest.residual);
    else
      std::printf("# rest state: %d Newton iterations, relative residual %.2e\n",
                  site.rest.iterations, site.rest.relativeResidual());
    for (const auto& c : comments) std::printf("# %s\n", c.c_str());
    std::printf("%10s %12s %6s %10s %s\n", "depth_um", "force_uN", "iters", "residual",
                "converged");
    for (const auto& p : r.curve)
      std::printf("%10.5f %12.6g %6d %10.2e %s%s\n", p.depth, p.force, p.iterations, p.residual,
                  p.converged ? "yes" : "NO", p.unloading ? "  (unloading)" : "");
  }
  // The CSV and the VTU of one run are written all or nothing.
  std::vector<std::pair<std::string, std::function<void(std::ostream&)>>> outputs;
  if (!a.csv.empty())
    outputs.emplace_back(a.csv, [&](std::ostream& o) { o << curveCsv(r.curve, comments); });
  StateFields fields;
  if (!a.vtu.empty()) {
    fields = stateFields(*site.model, ind.state(), ind.turgidState());
    outputs.emplace_back(a.vtu, [&](std::ostream& o) {
      writeVtu(o, *site.complex, ind.state(), fields.points, fields.triangles);
    });
  }
  writeFilesAtomically(outputs);
  if (!a.quiet && r.complete) {
    const double Eapp = hertzApparentModulus(r.curve, settings.indentation.probeRadius, mat.poissonRatio);
    std::printf("# secant stiffness %.6g uN/um, Hertz apparent modulus %.6g MPa\n",
                secantStiffness(r.curve), Eapp);
  }
  if (r.cancelled) {
    std::fprintf(stderr, "interrupted: %s; the %zu point(s) done are kept\n", r.message.c_str(),
                 r.curve.size());
    return kExitInterrupted;
  }
  if (!r.complete) {
    std::fprintf(stderr, "error: %s\n", r.message.c_str());
    return 3;
  }
  if (!r.message.empty()) std::fprintf(stderr, "warning: %s\n", r.message.c_str());
  return 0;
}

int runInfo(const std::string& path) {
  PlyInfo info;
  const CellComplex cc = readTissue(path, &info);
  const MeshQuality q = measureQuality(cc);
  std::printf("file             %s (%s)\n", path.c_str(), info.format.c_str());
  std::printf("%s", formatQuality(q).c_str());
  if (!info.ignoredElements.empty() || !info.ignoredProperties.empty()) {
    std::printf("ignored          ");
    for (const auto& e : info.ignoredElements) std::printf("element %s; ", e.c_str());
    for (const auto& p : info.ignoredProperties) std::printf("%s; ", p.c_str());
    std::printf("\n");
  }
  for (const auto& n : info.notes) std::printf("note:    %s\n", n.c_str());
  return q.validity.ok() ? 0 : 1;
}

struct BuildArgs {
  bool generate = false;
  int cells = 500;
  unsigned seed = 1;
  double diameter = 80, stemHeight = 8, capHeight = 34;
  std::string centroids, columns = "label,x,y,z";
  std::optional<double> baseZ;
  double realCellSize = 0;
  std::string box;
  double cellSize = 6.0;
  std::string cap;  // R,A
  double plate = 0;
  int rings = 12;
  std::string out;
  bool binary = false;
};

// The ring count of --cap and --plate: a lattice of about 3·rings² vertices.
int checkedRings(int rings) {
  if (rings < 2 || rings > 400)
    throw UsageError("--rings: expected 2 to 400 rings, got " + std::to_string(rings));
  return rings;
}

int runBuild(const BuildArgs& b) {
  if (b.out.empty()) throw UsageError("--out FILE.ply is required");
  checkOutputs({b.out}, {b.centroids});
  CellComplex cc;
  if (b.generate) {
    MeristemParams prm;
    prm.cells = b.cells;
    prm.seed = b.seed;
    prm.shape.radius = 0.5 * b.diameter;
    prm.shape.stemHeight = b.stemHeight;
    prm.shape.capHeight = b.capHeight;
    MeristemReport rep;
    cc = generateMeristem(prm, &rep);
    std::printf("generated a meristem in %.2f s: %d cells (L1 %d, L2 %d, inner %d), seed spacing "
                "%.2f um, %d short edges collapsed\n",
                rep.seconds, rep.cells, rep.l1Cells, rep.l2Cells, rep.innerCells, rep.cellSpacing,
                rep.voronoi.collapsedEdges);
  } else if (!b.centroids.empty()) {
    const CentroidTable table = readCentroids(b.centroids, CentroidColumns::parse(b.columns));
    RealTissueOptions opt;
    opt.baseZ = b.baseZ;
    opt.cellSize = b.realCellSize;
    RealTissueReport rep;
    cc = tissueFromCentroids(table, opt, &rep);
    std::printf("built a tissue from %zu centroids in %.2f s: cell size %.2f um, base plane z = "
                "%.2f um (%d centroids below it left out), alpha shape of %d triangles\n",
                table.points.size(), rep.seconds, rep.cellSize, rep.baseZ, rep.droppedBelowBase,
                rep.surfaceTriangles);
    if (!table.volumes.empty()) {
      std::vector<double> measured, built;
      const auto vol = cellVolumes(cc, cc.rest);
      for (size_t c = 0; c < vol.size(); ++c) {
        measured.push_back(table.volumes[rep.keptRows[c]]);
        built.push_back(vol[c]);
      }
      std::printf("cell volumes against the measured ones: correlation %.3f\n",
                  correlation(built, measured));
    }
    if (!rep.validity.ok())
      throw std::runtime_error("the tissue built from " + b.centroids +
                               " is not valid: " + rep.validity.summary());
  } else if (!b.box.empty()) {
    long long n[3];
    char rest = 0;
    if (std::sscanf(b.box.c_str(), "%lld,%lld,%lld%c", &n[0], &n[1], &n[2], &rest) != 3 ||
        n[0] < 1 || n[1] < 1 || n[2] < 1)
      throw UsageError("--box: expected three positive cell counts NX,NY,NZ, got '" + b.box + "'");
    if (n[0] > kMaxCells || n[1] > kMaxCells || n[2] > kMaxCells ||
        n[0] * n[1] * n[2] > kMaxCells)
      throw UsageError("--box: " + b.box + " is more than " + std::to_string(kMaxCells) +
                       " cells (the largest tissue built)");
    if (!(std::isfinite(b.cellSize) && b.cellSize > 0 && b.cellSize <= 1e3))
      throw UsageError("--cell-size: expected a size between 0 and 1000 um, got " +
                       std::to_string(b.cellSize));
    cc = boxTissue(static_cast<int>(n[0]), static_cast<int>(n[1]), static_cast<int>(n[2]),
                   b.cellSize);
  } else if (!b.cap.empty()) {
    double R = 0, A = 0;
    char rest = 0;
    if (std::sscanf(b.cap.c_str(), "%lf,%lf%c", &R, &A, &rest) != 2 || !std::isfinite(R) ||
        !std::isfinite(A) || !(A > 0) || !(A < R) || R > 1e4)
      throw UsageError("--cap: expected R,A in um with 0 < A < R <= 10000 (sphere radius, base "
                       "radius), got '" + b.cap + "'");
    cc = sphericalCap(R, A, checkedRings(b.rings), /*cell=*/0);
  } else if (b.plate != 0) {
    if (!(std::isfinite(b.plate) && b.plate > 0 && b.plate <= 1e4))
      throw UsageError("--plate: expected a radius between 0 and 10000 um, got " +
                       std::to_string(b.plate));
    const int rings = checkedRings(b.rings);
    // Two rings of clamped triangles beyond the rim: a built-in edge (zero slope).
    cc = latticeDisc(b.plate, rings, 2 * b.plate / rings, /*cell=*/0);
  } else {
    throw UsageError("choose what to build: --generate, --centroids FILE, --box NX,NY,NZ, "
                     "--cap R,A or --plate A");
  }
  writePly(b.out, cc, nullptr, b.binary);
  std::printf("wrote %s\n%s", b.out.c_str(), formatQuality(measureQuality(cc)).c_str());
  return 0;
}

struct FitArgs {
  IndentArgs model;
  std::vector<std::string> curves, plasmolysed;
  std::string fit = "E,p";
  std::string depthColumn, forceColumn, depthUnit, forceUnit;
  int maxPoints = 200, maxIterations = 30, simulatedDepths = 10;
  std::optional<double> contactHeight;
  std::string report, out;
};

// "FILE" or "FILE@x,y,z" (a site of its own): a table of indentation and force, or a JPK text
// export (recognised by its content).
FitCurve fitCurveArg(const std::string& arg, const MeasuredColumns& columns,
                     std::optional<double> pressure, std::optional<double> contactHeight,
                     bool quiet) {
  FitCurve c;
  std::string path = arg;
  const auto at = arg.rfind('@');
  if (at != std::string::npos && at + 1 < arg.size() && !std::filesystem::exists(arg)) {
    path = arg.substr(0, at);
    c.site = parseVec3(arg.substr(at + 1), "--curve " + arg);
  }
  if (!std::filesystem::exists(path)) throw UsageError("--curve: no file '" + path + "'");
  const std::string text = readTextFile(path, "curve");
  if (looksLikeJpkText(text)) {
    // A raw JPK curve: its approach converted to indentation at the estimated contact point.
    RawCurveOptions o;
    o.contactHeight = contactHeight;
    const RawCurveReading r = parseJpkForceCurve(text, path, o);
    c.data = r.curve;
    if (!quiet)
      std::printf("# %s: JPK approach of %zu points, k = %g N/m; contact at height %.4f um (%s), "
                  "baseline noise %.3g nN; %zu points in contact, to %.4g um and %.4g nN\n",
                  path.c_str(), r.height.size(), r.springConstant, r.contactHeight,
                  r.contactEstimated ? "estimated" : "given", 1e3 * r.noise, r.curve.depth.size(),
                  r.curve.depth.back(), 1e3 * r.curve.force.back());
  } else {
    c.data = parseMeasuredCurve(text, path, columns);  // names file, line, value
  }
  c.pressure = pressure;
  return c;
}

nlohmann::json fitReport(const FitResult& r, const FitArgs& a, const ExperimentSettings& s,
                         const std::vector<FitCurve>& curves) {
  using nlohmann::json;
  json values = json::object();
  for (const FitValue& v : r.values) {
    json e = {{"value", v.value}, {"unit", v.unit}, {"fitted", v.fitted}};
    if (v.fitted) {
      e["stderr"] = std::isfinite(v.error) ? json(v.error) : json(nullptr);
      e["ci95"] = std::isfinite(v.error) ? json::array({v.value - 1.96 * v.error,
                                                         v.value + 1.96 * v.error})
                                         : json(nullptr);
    }
    values[v.key] = e;
  }
  json corr = json::array();
  for (int i = 0; i < r.correlation.rows(); ++i) {
    json row = json::array();
    for (int j = 0; j < r.correlation.cols(); ++j)
      row.push_back(std::isfinite(r.correlation(i, j)) ? json(r.correlation(i, j)) : json(nullptr));
    corr.push_back(row);
  }
  json out = {{"converged", r.converged},
              {"message", r.message},
              {"iterations", r.iterations},
              {"evaluations", r.evaluations},
              {"values", values},
              {"correlation", {{"keys", r.fittedKeys}, {"matrix", corr}}},
              {"rms_uN", r.rms},
              {"rms_start_uN", r.rmsStart},
              {"identifiable", r.identifiable},
              {"advice", r.advice},
              {"intervals", "95 % = value +- 1.96 standard errors (normal approximation; "
                            "sigma^2 from the residual)"}};
  json cs = json::array();
  for (size_t i = 0; i < r.curves.size(); ++i) {
    const auto& c = r.curves[i];
    json e = {{"file", curves[i].data.name},
              {"points_used", c.depth.size()},
              {"depths_simulated", c.simulatedDepths},
              {"pressure_held_MPa", curves[i].pressure ? json(*curves[i].pressure) : json(nullptr)},
              {"hertz_apparent_modulus_MPa", c.hertzModulus},
              {"mesh_level", c.meshLevel}};
    if (curves[i].site) e["site_um"] = {curves[i].site->x(), curves[i].site->y(), curves[i].site->z()};
    e["mesh_error"] = c.meshError.estimated()
                          ? json({{"relative", c.meshError.relative}, {"method", c.meshError.method}})
                          : json(nullptr);
    cs.push_back(e);
  }
  out["curves"] = cs;
  out["settings"] = {{"fit", a.fit},
                     {"start", {{"E", s.material.youngModulus}, {"p", s.pressure},
                                {"h", s.material.thickness}}},
                     {"nu", s.material.poissonRatio},
                     {"bending", bendingLabel(s.material)},
                     {"probe_radius_um", s.indentation.probeRadius},
                     {"refine", a.model.refine}};
  return out;
}

int runFit(const FitArgs& a) {
  if (a.curves.empty() && a.plasmolysed.empty())
    throw UsageError("give at least one --curve FILE (or --plasmolysed-curve FILE)");
  const std::string meshPath = a.model.mesh.empty() ? defaultTissuePath() : a.model.mesh;
  std::vector<std::string> inputs = {meshPath};
  for (const auto& c : a.curves) inputs.push_back(c.substr(0, c.rfind('@')));
  for (const auto& c : a.plasmolysed) inputs.push_back(c.substr(0, c.rfind('@')));
  checkOutputs({a.report, a.out}, inputs);
  FitSettings fs;
  fs.start = experimentSettings(a.model);
  fs.fitE = fs.fitP = fs.fitH = fs.fitOffset = false;
  {
    std::stringstream ss(a.fit);
    std::string item;
    while (std::getline(ss, item, ',')) {
      if (item == "E") fs.fitE = true;
      else if (item == "p") fs.fitP = true;
      else if (item == "h") fs.fitH = true;
      else if (item == "offset") fs.fitOffset = true;
      else
        throw UsageError("--fit: '" + item + "' is not one of E, p, h, offset (comma-separated)");
    }
  }
  if (a.maxPoints < 2) throw UsageError("--max-points: at least 2, got " + std::to_string(a.maxPoints));
  fs.maxPoints = a.maxPoints;
  if (a.simulatedDepths != 0 && a.simulatedDepths < 2)
    throw UsageError("--simulated-depths: 0 (every point) or at least 2, got " +
                     std::to_string(a.simulatedDepths));
  fs.simulatedDepths = a.simulatedDepths;
  fs.maxIterations = a.maxIterations;
  MeasuredColumns columns{a.depthColumn, a.forceColumn, a.depthUnit, a.forceUnit};
  std::vector<FitCurve> curves;
  for (const auto& c : a.curves)
    curves.push_back(fitCurveArg(c, columns, std::nullopt, a.contactHeight, a.model.quiet));
  for (const auto& c : a.plasmolysed)
    curves.push_back(fitCurveArg(c, columns, 0.0, a.contactHeight, a.model.quiet));
  auto cc = std::make_shared<const CellComplex>(loadTissue(meshPath));

  Monitor monitor;
  monitor.cancel = &interrupted;
  const auto started = std::chrono::steady_clock::now();
  if (!a.model.quiet)
    monitor.stage = [&](const std::string& what) {
      std::fprintf(stderr, "[%6.2f s] %s\n",
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(),
                   what.c_str());
    };
  FitResult r;
  {
    InterruptScope scope;
    try {
      r = fitCurves(cc, fs, curves, monitor);
    } catch (const SolveFailure& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
      return 3;
    } catch (const Cancelled&) {
      std::fprintf(stderr, "interrupted: nothing written\n");
      return kExitInterrupted;
    }
  }
  if (!a.model.quiet) {
    std::printf("# %s\n", r.message.c_str());
    for (const FitValue& v : r.values) {
      if (v.fitted)
        std::printf("%-10s %12.6g %s  +- %.3g (95 %%: %.6g to %.6g)\n", v.key.c_str(), v.value,
                    v.unit.c_str(), v.error, v.value - 1.96 * v.error, v.value + 1.96 * v.error);
      else
        std::printf("%-10s %12.6g %s  (held)\n", v.key.c_str(), v.value, v.unit.c_str());
    }
    for (int i = 0; i < r.correlation.rows(); ++i)
      for (int j = i + 1; j < r.correlation.cols(); ++j)
        std::printf("# correlation %s-%s %.3f\n", r.fittedKeys[i].c_str(), r.fittedKeys[j].c_str(),
                    r.correlation(i, j));
    std::printf("# rms residual %.4g uN (at the start %.4g uN)\n", r.rms, r.rmsStart);
    for (size_t i = 0; i < r.curves.size(); ++i) {
      std::printf("# %s: %zu points (simulated at %d depths), mesh level %d",
                  curves[i].data.name.c_str(), r.curves[i].depth.size(),
                  r.curves[i].simulatedDepths, r.curves[i].meshLevel);
      // The automatic mesh's error at the fitted values: the simulated forces, and E (∝ them)
      // with them, carry it on top of the intervals above.
      if (r.curves[i].meshError.estimated())
        std::printf(" (estimated discretisation error +-%.2g %% of the force at the deepest "
                    "point, at the fitted values)",
                    100 * r.curves[i].meshError.relative);
      std::printf(", Hertz apparent modulus %.4g MPa\n", r.curves[i].hertzModulus);
    }
    if (!r.advice.empty()) std::printf("# %s\n", r.advice.c_str());
  }
  std::vector<std::pair<std::string, std::function<void(std::ostream&)>>> outputs;
  if (!a.report.empty())
    outputs.emplace_back(a.report, [&](std::ostream& o) {
      o << fitReport(r, a, fs.start, curves).dump(2) << "\n";
    });
  if (!a.out.empty())
    outputs.emplace_back(a.out, [&](std::ostream& o) {
      o << "curve,depth_um,measured_uN,simulated_uN,residual_uN\n";
      o.precision(10);
      for (size_t i = 0; i < r.curves.size(); ++i)
        for (size_t k = 0; k < r.curves[i].depth.size(); ++k)
          o << i + 1 << "," << r.curves[i].depth[k] << "," << r.curves[i].measured[k] << ","
            << r.curves[i].simulated[k] << ","
            << r.curves[i].simulated[k] - r.curves[i].measured[k] << "\n";
    });
  writeFilesAtomically(outputs);
  if (!r.converged) {
    std::fprintf(stderr, "error: the fit did not converge: %s\n", r.message.c_str());
    return 3;
  }
  if (!r.identifiable) std::fprintf(stderr, "warning: %s\n", r.advice.c_str());
  return 0;
}

struct MapArgs {
  IndentArgs model;
  std::string sites = "cells";
  std::optional<double> gridSpacing;
  std::string siteList;
  std::vector<std::string> vary;
  std::string out;
  int jobs = 0;
  std::string shard;
};

// "I/N" → (I, N) with 0 ≤ I < N.
std::pair<int, int> parseShard(const std::string& text) {
  const auto slash = text.find('/');
  int i = -1, n = 0;
  try {
    size_t u1 = 0, u2 = 0;
    if (slash == std::string::npos) throw std::invalid_argument(text);
    i = std::stoi(text.substr(0, slash), &u1);
    n = std::stoi(text.substr(slash + 1), &u2);
    if (u1 != slash || u2 != text.size() - slash - 1) throw std::invalid_argument(text);
  } catch (const std::exception&) {
    throw UsageError("--shard: expected I/N (shard I of N, 0 <= I < N), got '" + text + "'");
  }
  if (n < 1 || i < 0 || i >= n)
    throw UsageError("--shard: expected I/N with 0 <= I < N, got '" + text + "'");
  return {i, n};
}

// The CPUs this process may run on (its affinity mask: what Slurm, a cgroup or taskset gave it),
// at least 1.
int usableCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof set, &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

std::string hostName() {
  char buf[256] = {};
  if (gethostname(buf, sizeof buf - 1) != 0) return "unknown host";
  return buf;
}

int runMapCommand(const MapArgs& a, bool sweep) {
  if (a.model.depth && a.model.force) throw UsageError("give --depth or --force, not both");
  const std::string meshPath = a.model.mesh.empty() ? defaultTissuePath() : a.model.mesh;
  if (a.out.empty()) throw UsageError("--out: the results folder is required");
  auto [shard, shards] = a.shard.empty() ? std::pair<int, int>{0, 1} : parseShard(a.shard);
  MapPlan plan;
  // A map's mesh is made for forces unless --mesh-panels says otherwise.
  plan.settings =
      a.model.meshPanels ? experimentSettings(a.model) : mapSettings(experimentSettings(a.model));
  for (const auto& v : a.vary) {
    try {
      plan.vary.push_back(parseVariation(v));
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  }
  if (sweep && plan.vary.empty())
    throw UsageError("sweep: give at least one --vary NAME=A:B:N or NAME=V1,V2,...");
  auto cc = std::make_shared<const CellComplex>(loadTissue(meshPath));
  plan.tissue = std::filesystem::absolute(meshPath).lexically_normal().string();
  plan.tissueDigest = tissueDigest(*cc);
  std::vector<MapSite> leftOut;  // on the clamped base
  {
    std::vector<SiteKind> kinds;
    std::stringstream ss(a.sites);
    std::string word;
    try {
      while (std::getline(ss, word, ',')) kinds.push_back(parseSiteKind(word));
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--sites: ") + e.what());
    }
    try {
      plan.sites =
          mapSites(*cc, kinds, a.gridSpacing.value_or(std::numeric_limits<double>::quiet_NaN()),
                   a.siteList, plan.largestProbeRadius(), &leftOut);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  }
  if (!leftOut.empty() && !a.model.quiet) {
    std::string names;
    for (size_t i = 0; i < leftOut.size() && i < 5; ++i)
      names += (i ? ", " : "") + leftOut[i].label;
    if (leftOut.size() > 5) names += ", ...";
    std::fprintf(stderr,
                 "%zu site(s) left out: the probe (radius %g um) would reach the clamped base "
                 "there (%s)\n",
                 leftOut.size(), plan.largestProbeRadius(), names.c_str());
  }
  if (plan.sites.empty())
    throw UsageError("--sites " + a.sites + ": the tissue has no such site");
  try {
    plan.checkSize();
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  MapRunOptions options;
  options.outDir = a.out;
  options.shard = shard;
  options.shards = shards;
  options.jobs = a.jobs > 0 ? a.jobs : usableCpus();
  options.cancel = &interrupted;
  options.host = hostName();
  const bool terminal = !a.model.quiet && ::isatty(STDERR_FILENO);
  const bool lines = !a.model.quiet && !terminal && a.model.progress;
  bool shown = false;
  if (terminal || lines)
    options.progress = [&](const MapProgress& p) {
      const double rate = p.seconds > 0 ? p.done / p.seconds : 0;
      const double left = rate > 0 ? (p.todo - p.done) / rate : 0;
      std::fprintf(stderr, "%s[%7.1f s] %d/%d task(s) done%s, %.3g/s, about %.0f s left%s",
                   terminal ? "\r\033[K" : "", p.seconds, p.done, p.todo,
                   p.failed ? (" (" + std::to_string(p.failed) + " failed)").c_str() : "", rate,
                   left, terminal ? "" : "\n");
      std::fflush(stderr);
      shown = terminal;
    };
  if (!a.model.quiet)
    std::fprintf(stderr, "%s of %s: %zu site(s) x %d parameter set(s) = %d task(s); shard %d/%d, "
                         "%d worker(s), results in %s\n",
                 sweep ? "sweep" : "map", meshPath.c_str(), plan.sites.size(),
                 plan.parameterSets(), plan.taskCount(), shard, shards, options.jobs,
                 a.out.c_str());
  MapRunSummary r;
  {
    InterruptScope scope;
    r = runMap(cc, plan, options);
  }
  if (shown) std::fprintf(stderr, "\n");
  if (!a.model.quiet) {
    std::fprintf(stderr, "%d task(s) of this shard: %d done now (%d not converged), %d done before\n",
                 r.shardTasks, r.done, r.failed, r.skipped);
    for (const auto& w : r.written) std::fprintf(stderr, "wrote %s\n", w.c_str());
    if (!r.complete && !r.cancelled)
      std::fprintf(stderr, "the other shards' tasks are not in %s yet: when every shard is done, "
                           "gather them with: tissueprobe-cli merge DIR... --out DIR\n",
                   a.out.c_str());
  }
  if (r.cancelled) {
    std::fprintf(stderr, "interrupted: the %d task(s) done are kept in %s; run the same command "
                         "again to go on\n", r.done, a.out.c_str());
    return kExitInterrupted;
  }
  const auto all = readResults(a.out, plan);
  int failed = 0;
  for (int t = shard; t < plan.taskCount(); t += shards)
    if (all[t].task >= 0 && !all[t].converged()) ++failed;
  if (failed) {
    std::fprintf(stderr, "error: %d task(s) of this shard did not converge (status and message "
                         "in the table and in %s/results)\n", failed, a.out.c_str());
    return 3;
  }
  return 0;
}

int runMerge(const std::vector<std::string>& dirs, const std::string& out, const std::string& mesh,
             bool quiet) {
  std::shared_ptr<const CellComplex> cc;
  if (!mesh.empty()) cc = std::make_shared<const CellComplex>(loadTissue(mesh));
  const MergeSummary m = mergeMaps(dirs, out, cc);
  if (!m.missing.empty()) {
    std::string list;
    for (size_t k = 0; k < m.missing.size() && k < 20; ++k)
      list += (k ? ", " : "") + std::to_string(m.missing[k]);
    if (m.missing.size() > 20) list += ", ...";
    std::fprintf(stderr, "error: %zu of %d task(s) are in none of the folders (%s): run their "
                         "shards again with --out %s (done tasks are skipped), then merge\n",
                 m.missing.size(), m.tasks, list.c_str(), out.c_str());
    return 3;
  }
  if (!quiet) {
    std::fprintf(stderr, "merged %d task(s) from %zu folder(s)\n", m.found, dirs.size());
    for (const auto& w : m.written) std::fprintf(stderr, "wrote %s\n", w.c_str());
  }
  return 0;
}

// The tissue, wall, turgor, probe and site options shared by indent and fit.
void addModelOptions(CLI::App* cmd, IndentArgs& a) {
  cmd->add_option("--mesh", a.mesh, "Tissue file (PLY); default: the shipped default tissue")
      ->check(CLI::ExistingFile);
  cmd->add_option("--E", a.E, "Young's modulus of the walls, MPa")->capture_default_str();
  cmd->add_option("--nu", a.nu, "Poisson ratio of the walls")->capture_default_str();
  cmd->add_option("--thickness", a.thickness, "Wall thickness h, um")->capture_default_str();
  cmd->add_option("--pressure", a.pressure, "Turgor pressure of every cell, MPa")
      ->capture_default_str();
  cmd->add_option("--bending", a.bending,
                     "Bending model: koiter (plate energy with the walls' nu) | hinge | linear "
                     "(the published model) | none")
      ->check(CLI::IsMember({"koiter", "hinge", "linear", "none"}))
      ->capture_default_str();
  cmd->add_option("--junctions", a.junctions,
                     "How walls meeting at a junction share rotation under koiter bending: "
                     "hinged (they pivot; the outer surface bends as one sheet) | rigid (the "
                     "angles between them kept)")
      ->check(CLI::IsMember({"hinged", "rigid"}))
      ->capture_default_str();
  cmd->add_option("--probe-radius", a.probeRadius, "Radius of the spherical probe, um")
      ->capture_default_str();
  cmd->add_option("--site", a.site,
                     "Indentation site x,y,z in um; the nearest outer-surface point is used "
                     "(default: the top of the tissue as given, the same material point "
                     "whatever E, nu, h and p are)");
  cmd->add_option("--axis", a.axis,
                     "Probe direction dx,dy,dz into the tissue (default: the inward normal of "
                     "the tissue as given at the site)");
  cmd->add_option("--refine", a.refine,
                  "Mesh at the site: auto (refine level by level until the estimated "
                  "discretisation error is within --mesh-tolerance) or a fixed level (0 = the "
                  "tissue as given; level L has triangles of probe radius / 2^(L-1) under the "
                  "probe, graded out to the tissue's own)")
      ->capture_default_str();
  cmd->add_option("--mesh-tolerance", a.meshTolerance,
                  "Relative discretisation error asked of --refine auto (of the force at the "
                  "deepest point, or the depth at the largest force)")
      ->capture_default_str();
  cmd->add_flag("--junction-band", a.junctionBand,
                "Also refine a band along the junctions of the walls around the site to the "
                "width of their bending layer under turgor, sqrt(D/N) (slower; for checking a "
                "result's sensitivity to the junctions' layers)");
  cmd->add_option("--mesh-panels", a.meshPanels,
                  "Longest edge anywhere on the walls refined around the site at level 3, in "
                  "cell sizes, halved every level (default 0.35 for indent and fit, fine enough "
                  "for a speckle-free stress picture; 0.7 for map and sweep, which report "
                  "forces only)");
  cmd->add_flag("--quiet", a.quiet, "Print nothing but errors");
}

}  // namespace

int main(int argc, char** argv) {
  tp::keepFreedMemory();
  CLI::App app{"TissueProbe command line: AFM-style spherical indentation of a plant tissue.\n"
               "Units: lengths in um, moduli and pressures in MPa, forces in uN."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "tissueprobe-cli " TP_VERSION);

  IndentArgs ia;
  auto* indent = app.add_subcommand("indent", "Run one indentation and print the force-depth curve");
  addModelOptions(indent, ia);
  auto* depthOpt = indent->add_option("--depth", ia.depth,
                                      "Displacement control: final depth from first contact, um "
                                      "(default 0.5)");
  auto* forceOpt = indent->add_option("--force", ia.force, "Force control: final force, uN");
  depthOpt->excludes(forceOpt);
  indent->add_option("--steps", ia.steps, "Number of loading steps")->capture_default_str();
  indent->add_flag("--unload", ia.unload, "Unload back to zero after loading");
  indent->add_flag("--no-predictor", ia.noPredictor,
                   "Start each step from the last equilibrium with the probe moved (as the "
                   "published method did) instead of extrapolating from the last three");
  indent->add_option("--csv", ia.csv, "Write the curve as CSV (depth_um,force_uN,iterations,"
                                      "residual,converged)");
  indent->add_option("--vtu", ia.vtu,
                     "Write the final deformed state with per-triangle stress (MPa) for ParaView");
  indent->add_option("--tolerance", ia.tolerance,
                     "Newton tolerance on the residual relative to the load scale")
      ->capture_default_str();
  indent->add_option("--solver", ia.solver,
                     "Equilibrium solver: newton (Newton + CHOLMOD) or implicit-euler-cg (the "
                     "published method: implicit Euler, Rayleigh damping, CG, run until rest)")
      ->check(CLI::IsMember({"newton", "implicit-euler-cg"}))
      ->capture_default_str();
  indent->add_flag("--verbose", ia.verbose, "Print every Newton iteration");
  indent->add_flag("--progress", ia.progress,
                   "A line per point of the curve on stderr also when it is not a terminal "
                   "(on a terminal one progress line is always rewritten in place)");

  FitArgs fa;
  auto* fit = app.add_subcommand(
      "fit", "Fit the walls' Young modulus, the turgor and the wall thickness to measured "
             "force-indentation curves at a site (Levenberg-Marquardt, exact derivatives)");
  addModelOptions(fit, fa.model);
  fit->add_option("--curve", fa.curves,
                  "A measured curve: a CSV/TSV table of indentation and force, or a JPK force-"
                  "curve text export (its approach converted at the contact point); FILE@x,y,z "
                  "gives it a site of its own; repeat for several")
      ->take_all();
  fit->add_option("--plasmolysed-curve", fa.plasmolysed,
                  "A measured curve of the plasmolysed tissue (turgor held at 0)")
      ->take_all();
  fit->add_option("--fit", fa.fit, "What to fit: a comma-separated subset of E, p, h, offset "
                                   "(a contact-point offset per curve); the other values are "
                                   "held at --E, --pressure, --thickness")
      ->capture_default_str();
  fit->add_option("--depth-column", fa.depthColumn,
                  "The indentation column: header name or 1-based position (default: the first "
                  "named depth/indentation/delta/separation)");
  fit->add_option("--force-column", fa.forceColumn,
                  "The force column: header name or position (default: the first named force/F)");
  fit->add_option("--depth-unit", fa.depthUnit, "m, mm, um or nm (default: from the header)");
  fit->add_option("--force-unit", fa.forceUnit, "N, mN, uN, nN or pN (default: from the header)");
  fit->add_option("--contact-height", fa.contactHeight,
                  "JPK curves: the piezo height at contact, um (default: estimated where the "
                  "force leaves the baseline's noise)");
  fit->add_option("--max-points", fa.maxPoints,
                  "Measured points compared per curve (evenly spread over its depths)")
      ->capture_default_str();
  fit->add_option("--simulated-depths", fa.simulatedDepths,
                  "Depths simulated per curve, evenly spread over its points; the force between "
                  "them, and its derivatives, are the cubic spline through them. 0: every point")
      ->capture_default_str();
  fit->add_option("--max-iterations", fa.maxIterations, "Levenberg-Marquardt iterations at most")
      ->capture_default_str();
  fit->add_option("--tolerance", fa.model.tolerance,
                  "Newton tolerance of the simulations (at most 1e-10 is used)")
      ->capture_default_str();
  fit->add_option("--report", fa.report,
                  "Write a JSON report: values under their option names (E, p, h) with standard "
                  "errors and 95 % intervals, correlations, residual, identifiability");
  fit->add_option("--out", fa.out,
                  "Write the curves as used, simulated at the fit, as CSV "
                  "(curve,depth_um,measured_uN,simulated_uN,residual_uN)");

  MapArgs ma, sa;
  CLI::App* mapCmds[2] = {nullptr, nullptr};
  for (int k = 0; k < 2; ++k) {
    MapArgs& m = k == 0 ? ma : sa;
    m.model.steps = 5;
    auto* cmd = mapCmds[k] = app.add_subcommand(
        k == 0 ? "map" : "sweep",
        k == 0 ? "A stiffness map: the indentation at many sites of the tissue (cell middles, "
                 "anticlinal junctions, a grid, a list), in parallel, in shards, resumable"
               : "A parameter sweep: the indentation over a grid of parameter values (and "
                 "sites), in parallel, in shards, resumable");
    addModelOptions(cmd, m.model);
    cmd->remove_option(cmd->get_option("--site"));
    auto* d = cmd->add_option("--depth", m.model.depth,
                              "Displacement control: final depth from first contact, um "
                              "(default 0.5)");
    auto* f = cmd->add_option("--force", m.model.force, "Force control: final force, uN");
    d->excludes(f);
    cmd->add_option("--steps", m.model.steps, "Loading steps per site")->capture_default_str();
    cmd->add_option(
           "--sites", m.sites,
           "Which sites: cells (the middle of every cell's outer wall), junctions "
           "(every anticlinal junction on the surface), grid (a square grid seen from "
           "above), list (--site-list); comma-separated for several. Cells, junctions and grid "
           "points where the probe would reach the clamped base are left out (said on "
           "stderr)")
        ->capture_default_str();
    cmd->add_option("--grid-spacing", m.gridSpacing,
                    "Spacing of --sites grid, um (default: the mean cell size)");
    cmd->add_option("--site-list", m.siteList, "Sites x,y,z in um, one per line (--sites list)")
        ->check(CLI::ExistingFile);
    if (k == 1)
      cmd->add_option("--vary", m.vary,
                      "A parameter and its values: NAME=A:B:N (N values from A to B) or "
                      "NAME=V1,V2,...; NAME is E, nu, h, p or probe-radius; repeat for a grid")
          ->take_all()
          ->required();
    cmd->add_option("--out", m.out,
                    "Results folder: plan.json, results/ (one file per finished task), map.csv "
                    "and (maps) map-surface.vtu when every task is done, run.log")
        ->required();
    cmd->add_option("--jobs", m.jobs,
                    "Worker threads (default: one per CPU this process may use, e.g. Slurm's "
                    "allocation)");
    cmd->add_option("--shard", m.shard,
                    "Run only shard I of N (tasks with index = I mod N), e.g. "
                    "$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT");
    cmd->add_flag("--progress", m.model.progress,
                  "A progress line per task on stderr also when it is not a terminal");
  }

  std::vector<std::string> mergeDirs;
  std::string mergeOut, mergeMesh;
  bool mergeQuiet = false;
  auto* merge = app.add_subcommand(
      "merge", "Gather the results folders of the shards of one map or sweep into one folder, "
               "with the same table and surface as a single run");
  merge->add_option("dirs", mergeDirs, "The shards' results folders")->required()
      ->check(CLI::ExistingDirectory);
  merge->add_option("--out", mergeOut, "The merged results folder")->required();
  merge->add_option("--mesh", mergeMesh,
                    "The tissue file, when it is not at the path recorded in plan.json")
      ->check(CLI::ExistingFile);
  merge->add_flag("--quiet", mergeQuiet, "Print nothing but errors");

  std::string infoPath;
  auto* info = app.add_subcommand("info", "Cells, walls, vertices, triangles, closedness, volume "
                                          "and quality of a tissue file");
  info->add_option("file", infoPath, "Tissue file (PLY)")->required()->check(CLI::ExistingFile);

  BuildArgs ba;
  auto* build = app.add_subcommand("build", "Make a tissue file");
  build->add_flag("--generate", ba.generate, "A floral meristem: a dome of Voronoi cells in L1, L2 "
                                              "and inner layers, base clamped");
  build->add_option("--cells", ba.cells, "Meristem: number of cells")->capture_default_str();
  build->add_option("--seed", ba.seed, "Meristem: random seed")->capture_default_str();
  build->add_option("--diameter", ba.diameter, "Meristem: dome diameter, um")->capture_default_str();
  build->add_option("--stem-height", ba.stemHeight, "Meristem: height of the stem below the dome, um")
      ->capture_default_str();
  build->add_option("--cap-height", ba.capHeight, "Meristem: height of the dome above the stem, um")
      ->capture_default_str();
  build->add_option("--centroids", ba.centroids,
                    "A real tissue from a table of cell centroids (CSV or TSV, um): Voronoi cells "
                    "closed by the alpha shape of the centroids pushed out by half a cell")
      ->check(CLI::ExistingFile);
  build->add_option("--columns", ba.columns,
                    "Centroids: the label,x,y,z[,volume] columns, by header name or 1-based "
                    "position")
      ->capture_default_str();
  build->add_option("--base-z", ba.baseZ,
                    "Centroids: height of the clamped base plane, um (default: lowest centroid "
                    "plus one cell)");
  build->add_option("--real-cell-size", ba.realCellSize,
                    "Centroids: typical cell size, um (default: from the nearest-neighbour "
                    "distances)");
  build->add_option("--box", ba.box, "A block of NX,NY,NZ cubic cells, base clamped");
  build->add_option("--cell-size", ba.cellSize, "Cell size, um")->capture_default_str();
  build->add_option("--cap", ba.cap,
                    "A spherical cap R,A (um): sphere radius R, base radius A, rim clamped, the "
                    "wall of one cell below it (a pressure inflates it); for the point load on a "
                    "thin sphere (Reissner; Vella et al. 2012 with pressure), take A several "
                    "sqrt(R h)");
  build->add_option("--plate", ba.plate,
                    "A flat circular plate of radius A (um), edge built in (clamped, zero slope), "
                    "the wall of one cell below it");
  build->add_option("--rings", ba.rings, "Cap and plate: lattice rings from the centre to the rim")
      ->capture_default_str();
  build->add_option("--out", ba.out, "Output tissue file (PLY)")->required();
  build->add_flag("--binary", ba.binary, "Write binary little-endian PLY");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Help and version exit 0; every parse error exits 2 like the other usage errors.
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    if (*indent) return runIndent(ia);
    if (*fit) return runFit(fa);
    if (*mapCmds[0]) return runMapCommand(ma, false);
    if (*mapCmds[1]) return runMapCommand(sa, true);
    if (*merge) return runMerge(mergeDirs, mergeOut, mergeMesh, mergeQuiet);
    if (*info) return runInfo(infoPath);
    if (*build) return runBuild(ba);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const WriteError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return kExitCannotWrite;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}
