// tissueprobe-cli: command-line runs of the TissueProbe core.
//   indent  one indentation curve (CSV, VTU)
//   info    size, closedness and quality of a tissue file
//   build   make a tissue file
// Units everywhere: µm, MPa, µN.

#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <functional>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <unistd.h>

#include "experiment/Analysis.h"
#include "experiment/Experiment.h"
#include "experiment/Indentation.h"
#include "experiment/Stress.h"
#include "io/AtomicFile.h"
#include "io/Centroids.h"
#include "io/CurveCsv.h"
#include "io/Paths.h"
#include "io/Ply.h"
#include "io/TissueFiles.h"
#include "io/Vtu.h"
#include "mesh/Quality.h"
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

CellComplex loadTissue(const std::string& path) {
  PlyInfo info;
  CellComplex cc = readTissue(path, &info);
  const std::string problem = simulationProblem(cc);
  if (!problem.empty()) throw std::runtime_error(path + ": " + problem);
  return cc;
}

struct IndentArgs {
  std::string mesh;
  double E = 100.0, nu = 0.49, thickness = 0.2, pressure = 0.8;
  std::string bending = "koiter";
  std::string junctions = "hinged";
  double probeRadius = 1.0;
  std::string site, axis;
  std::optional<double> depth, force;
  int steps = 10;
  bool unload = false;
  bool noPredictor = false;
  std::string refine = "auto";
  double meshTolerance = 0.03;
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
      << " triangles, smallest angle " << site.refinement.minAngleDeg << " deg";
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
  std::string out;
  bool binary = false;
};

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
  } else {
    throw UsageError("choose what to build: --generate, --centroids FILE or --box NX,NY,NZ");
  }
  writePly(b.out, cc, nullptr, b.binary);
  std::printf("wrote %s\n%s", b.out.c_str(), formatQuality(measureQuality(cc)).c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"TissueProbe command line: AFM-style spherical indentation of a plant tissue.\n"
               "Units: lengths in um, moduli and pressures in MPa, forces in uN."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "tissueprobe-cli 0.1");

  IndentArgs ia;
  auto* indent = app.add_subcommand("indent", "Run one indentation and print the force-depth curve");
  indent->add_option("--mesh", ia.mesh, "Tissue file (PLY); default: the shipped default tissue")
      ->check(CLI::ExistingFile);
  indent->add_option("--E", ia.E, "Young's modulus of the walls, MPa")->capture_default_str();
  indent->add_option("--nu", ia.nu, "Poisson ratio of the walls")->capture_default_str();
  indent->add_option("--thickness", ia.thickness, "Wall thickness h, um")->capture_default_str();
  indent->add_option("--pressure", ia.pressure, "Turgor pressure of every cell, MPa")
      ->capture_default_str();
  indent->add_option("--bending", ia.bending,
                     "Bending model: koiter (plate energy with the walls' nu) | hinge | linear "
                     "(the published model) | none")
      ->check(CLI::IsMember({"koiter", "hinge", "linear", "none"}))
      ->capture_default_str();
  indent->add_option("--junctions", ia.junctions,
                     "How walls meeting at a junction share rotation under koiter bending: "
                     "hinged (they pivot; the outer surface bends as one sheet) | rigid (the "
                     "angles between them kept)")
      ->check(CLI::IsMember({"hinged", "rigid"}))
      ->capture_default_str();
  indent->add_option("--probe-radius", ia.probeRadius, "Radius of the spherical probe, um")
      ->capture_default_str();
  indent->add_option("--site", ia.site,
                     "Indentation site x,y,z in um; the nearest outer-surface point is used "
                     "(default: the top of the tissue)");
  indent->add_option("--axis", ia.axis,
                     "Probe direction dx,dy,dz into the tissue (default: the inward surface "
                     "normal at the site)");
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
  indent->add_option("--refine", ia.refine,
                     "Mesh at the site: auto (refine level by level until the estimated "
                     "discretisation error is within --mesh-tolerance) or a fixed level (0 = the "
                     "tissue as given; level L has triangles of probe radius / 2^(L-1) under the "
                     "probe, graded out to the tissue's own)")
      ->capture_default_str();
  indent->add_option("--mesh-tolerance", ia.meshTolerance,
                     "Relative discretisation error asked of --refine auto (of the force at the "
                     "deepest point, or the depth at the largest force)")
      ->capture_default_str();
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
  indent->add_flag("--quiet", ia.quiet, "Print nothing but errors");
  indent->add_flag("--progress", ia.progress,
                   "A line per point of the curve on stderr also when it is not a terminal "
                   "(on a terminal one progress line is always rewritten in place)");

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
