// tissueprobe-cli: command-line runs of the TissueProbe core.
//   indent  one indentation curve (CSV, VTU)
//   info    size, closedness and quality of a tissue file
//   build   make a tissue file
// Units everywhere: µm, MPa, µN.

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "experiment/Analysis.h"
#include "experiment/Indentation.h"
#include "experiment/Stress.h"
#include "io/Centroids.h"
#include "io/CurveCsv.h"
#include "io/Paths.h"
#include "io/Ply.h"
#include "io/Vtu.h"
#include "mesh/Quality.h"
#include "tissue/Meristem.h"
#include "tissue/RealTissue.h"
#include "tissue/Refine.h"
#include "tissue/Shapes.h"

namespace {

using namespace tp;

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

Vec3 parseVec3(const std::string& text, const std::string& option) {
  std::stringstream ss(text);
  Vec3 v;
  std::string item;
  int k = 0;
  while (std::getline(ss, item, ',')) {
    if (k >= 3) break;
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
  CellComplex cc = readPly(path, &info);
  const std::string problem = simulationProblem(cc);
  if (!problem.empty()) throw std::runtime_error(path + ": " + problem);
  return cc;
}

struct IndentArgs {
  std::string mesh;
  double E = 100.0, nu = 0.49, thickness = 0.2, pressure = 0.8;
  std::string bending = "hinge";
  double probeRadius = 1.0;
  std::string site, axis;
  std::optional<double> depth, force;
  int steps = 10;
  bool unload = false;
  bool noPredictor = false;
  int refine = 0;
  double refineRadius = 0;
  std::string csv, vtu;
  double tolerance = 1e-8;
  std::string solver = "newton";
  bool verbose = false, quiet = false;
};

int runIndent(const IndentArgs& a) {
  if (a.depth && a.force) throw UsageError("give --depth or --force, not both");
  if (a.steps < 1) throw UsageError("--steps must be at least 1 (got " + std::to_string(a.steps) + ")");
  const std::string meshPath = a.mesh.empty() ? defaultTissuePath() : a.mesh;
  auto cc = std::make_shared<CellComplex>(loadTissue(meshPath));
  std::optional<Vec3> site;
  if (!a.site.empty()) site = parseVec3(a.site, "--site");
  if (a.refine < 0 || a.refine > 6)
    throw UsageError("--refine must be between 0 and 6 (got " + std::to_string(a.refine) + ")");

  Material mat;
  mat.youngModulus = a.E;
  mat.poissonRatio = a.nu;
  mat.thickness = a.thickness;
  mat.bending = parseBendingModel(a.bending);
  mat.validate();
  if (!std::isfinite(a.pressure)) throw UsageError("--pressure must be finite");
  IndentationSettings s;
  s.probeRadius = a.probeRadius;
  s.site = site;
  if (!a.axis.empty()) s.axis = parseVec3(a.axis, "--axis");
  s.steps = a.steps;
  s.unload = a.unload;
  s.predictor = !a.noPredictor;
  if (a.force) {
    if (!(std::isfinite(*a.force) && *a.force > 0)) throw UsageError("--force must be positive");
    s.control = Control::Force;
    s.maxForce = *a.force;
  } else {
    s.maxDepth = a.depth.value_or(0.5);
    if (!(std::isfinite(s.maxDepth) && s.maxDepth > 0)) throw UsageError("--depth must be positive");
  }
  if (a.refine > 0) {
    // Find the site on the turgid unrefined tissue, refine the rest mesh around that material
    // point, and indent the refined tissue at the same place.
    Model coarse(cc, mat);
    coarse.setUniformPressure(a.pressure);
    Indentation probe(coarse, s);
    probe.prepare();
    if (!probe.prepared()) {
      std::fprintf(stderr, "error: %s\n", probe.lastMessage().c_str());
      return 3;
    }
    const ProbePlacement& pl = probe.placement();
    const Vec3 at = restPositionOf(coarse, probe.turgidState(), pl.site, pl.triangle);
    // Default radius: the larger of three probe radii and one cell, so the walls under the probe
    // are refined whole.
    double volume = 0;
    for (double v : cellVolumes(*cc, cc->rest)) volume += v;
    const double cell = cc->cellCount() ? std::cbrt(volume / cc->cellCount()) : 0.0;
    const double radius = a.refineRadius > 0 ? a.refineRadius : std::max(3.0 * a.probeRadius, cell);
    RefineReport rr;
    cc = std::make_shared<CellComplex>(refineNear(*cc, at, radius, a.refine, &rr));
    s.site = pl.site;
    if (!a.quiet)
      std::printf("# refined %d level(s) within %g um of the site: %d vertices (+%d), %d "
                  "triangles, min angle %.2f deg\n",
                  a.refine, radius, cc->vertexCount(), rr.addedVertices, cc->triangleCount(),
                  rr.minAngleDeg);
  }
  Model model(cc, mat);
  model.setUniformPressure(a.pressure);

  SolverOptions so;
  so.kind = parseSolverKind(a.solver);
  if (so.kind == SolverKind::ImplicitEulerCG && a.force)
    throw UsageError("--solver implicit-euler-cg supports --depth only");
  so.tolerance = a.tolerance;
  so.verbose = a.verbose;
  Indentation ind(model, s, so);

  if (!a.quiet) {
    std::printf("# tissue %s: %d cells, %d vertices, %d triangles\n", meshPath.c_str(),
                cc->cellCount(), cc->vertexCount(), cc->triangleCount());
    std::printf("# E = %g MPa, nu = %g, h = %g um, p = %g MPa, bending %s, probe radius %g um\n",
                mat.youngModulus, mat.poissonRatio, mat.thickness, a.pressure,
                toString(mat.bending).c_str(), s.probeRadius);
  }
  const SolveReport rest = ind.prepare();
  if (!ind.prepared()) {
    std::fprintf(stderr, "error: %s\n", ind.lastMessage().c_str());
    return 3;
  }
  const ProbePlacement& pl = ind.placement();
  if (!a.quiet) {
    std::printf("# turgid state: %d Newton iterations, relative residual %.2e\n", rest.iterations,
                rest.relativeResidual());
    std::printf("# site (%.4g, %.4g, %.4g) um, axis (%.4f, %.4f, %.4f)\n", pl.site.x(),
                pl.site.y(), pl.site.z(), pl.axis.x(), pl.axis.y(), pl.axis.z());
    std::printf("%10s %12s %6s %10s %s\n", "depth_um", "force_uN", "iters", "residual",
                "converged");
  }
  const auto curve = ind.run([&](int, int) {}, nullptr);
  if (!a.quiet)
    for (const auto& p : curve)
      std::printf("%10.5f %12.6g %6d %10.2e %s%s\n", p.depth, p.force, p.iterations, p.residual,
                  p.converged ? "yes" : "NO", p.unloading ? "  (unloading)" : "");
  if (!a.csv.empty()) writeCurveCsv(a.csv, curve);
  if (!a.vtu.empty()) {
    const StressField st = computeStress(model, ind.state());
    const int T = cc->triangleCount(), V = cc->vertexCount();
    VtuField sigma{"cauchy_stress_MPa", 9, {}}, s1{"principal_max_MPa", 1, {}},
        s2{"principal_min_MPa", 1, {}}, vm{"von_mises_MPa", 1, {}}, sed{"strain_energy_density_MPa", 1, {}},
        bend{"bending_energy_density_MPa", 1, {}};
    for (int t = 0; t < T; ++t) {
      const auto& ts = st.triangles[t];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) sigma.values.push_back(ts.cauchy(i, j));
      s1.values.push_back(ts.principalMax);
      s2.values.push_back(ts.principalMin);
      vm.values.push_back(ts.vonMises);
      sed.values.push_back(ts.energyDensity);
      bend.values.push_back(st.bendingEnergyDensity[t]);
    }
    VtuField disp{"displacement_um", 3, {}}, dispRest{"displacement_from_rest_um", 3, {}};
    for (int v = 0; v < V; ++v)
      for (int k = 0; k < 3; ++k) {
        disp.values.push_back(ind.state()(k, v) - ind.turgidState()(k, v));
        dispRest.values.push_back(ind.state()(k, v) - cc->rest(k, v));
      }
    writeVtu(a.vtu, *cc, ind.state(), {disp, dispRest}, {sigma, s1, s2, vm, sed, bend});
  }
  const bool ok = !curve.empty() && curve.back().converged;
  if (!a.quiet) {
    const double Eapp = hertzApparentModulus(curve, s.probeRadius, mat.poissonRatio);
    std::printf("# secant stiffness %.6g uN/um, Hertz apparent modulus %.6g MPa\n",
                secantStiffness(curve), Eapp);
  }
  if (!ok) {
    std::fprintf(stderr, "error: %s\n", ind.lastMessage().c_str());
    return 3;
  }
  return 0;
}

int runInfo(const std::string& path) {
  PlyInfo info;
  const CellComplex cc = readPly(path, &info);
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
    int n[3];
    if (std::sscanf(b.box.c_str(), "%d,%d,%d", &n[0], &n[1], &n[2]) != 3 || n[0] < 1 || n[1] < 1 ||
        n[2] < 1)
      throw UsageError("--box: expected three positive cell counts NX,NY,NZ, got '" + b.box + "'");
    cc = boxTissue(n[0], n[1], n[2], b.cellSize);
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
  indent->add_option("--bending", ia.bending, "Bending model: hinge | linear | none")
      ->check(CLI::IsMember({"hinge", "linear", "none"}))
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
                     "Subdivide the walls near the site this many times (each triangle into four, "
                     "conforming transitions)")
      ->capture_default_str();
  indent->add_option("--refine-radius", ia.refineRadius,
                     "Radius of the refined region around the site, um (default: the larger of 3 "
                     "probe radii and one cell size)");
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
    return app.exit(e);
  }
  try {
    if (*indent) return runIndent(ia);
    if (*info) return runInfo(infoPath);
    if (*build) return runBuild(ba);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}
