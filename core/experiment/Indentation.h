#pragma once
// The indentation protocol (DESIGN.md §1): bring the tissue to rest under its turgor pressure,
// choose a site on its outer surface and an axis (default: the inward normal there), bring the
// probe to first contact with that state, then load under displacement control (a depth
// schedule) or force control (a force schedule; the probe's travel is an unknown), optionally
// unload, warm-starting every step from the previous ones. A step that fails is retried in
// smaller sub-steps; if it still fails the point is reported as not converged and the state
// stays at the last equilibrium. The turgor pressures are those set on the model.
// Units: µm, µN, MPa.

#include <atomic>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "mechanics/Model.h"
#include "solver/Solver.h"

namespace tp {

struct CurvePoint {
  double depth = 0;      // µm, probe travel from first contact
  double force = 0;      // µN, probe force on the tissue along the axis
  int iterations = 0;    // Newton iterations (all sub-steps)
  double residual = 0;   // final relative residual
  bool converged = false;
  bool unloading = false;
};

enum class Control { Depth, Force };

struct IndentationSettings {
  double probeRadius = 1.0;         // µm
  std::optional<Vec3> site;         // µm; nearest outer-surface point is used; default: the top
  // µm: a material point of the outer surface given by its rest position; the site is where it
  // is in the turgid state (overrides `site`; used to keep one material point across meshes).
  std::optional<Vec3> restSite;
  std::optional<Vec3> axis;         // into the tissue; default: inward surface normal at the site
  Control control = Control::Depth;
  double maxDepth = 0.5;            // µm (depth control)
  double maxForce = 5.0;            // µN (force control; ~0.5 µm on the turgid default meristem)
  int steps = 10;
  bool unload = false;
  int maxSubdivisions = 5;          // a failed step is split up to 2^maxSubdivisions times
  // Start each step from the polynomial through the last equilibria (true), or from the last
  // equilibrium with only the probe moved (false: what the published method did).
  bool predictor = true;
};

/// The control values of the schedule in order: `steps` equal steps up to the maximum depth (or
/// force), then, when unloading, back down to zero.
std::vector<double> scheduleTargets(const IndentationSettings& settings);

/// Where the probe touches: site on the surface, unit axis into the tissue, and the probe centre
/// at first contact.
struct ProbePlacement {
  Vec3 site = Vec3::Zero();
  Vec3 axis = -Vec3::UnitZ();
  Vec3 contactCenter = Vec3::Zero();
  int triangle = -1;  // outer triangle holding the site
};

/// Closest point to `target` on the outer surface, skipping fully clamped triangles.
Vec3 nearestSurfacePoint(const Model& model, const Points& x, const Vec3& target, int* triangle);
/// The top of the tissue: the highest outer-surface point on the vertical through the centre of
/// the free outer surface (falls back to the highest free vertex).
Vec3 topSurfacePoint(const Model& model, const Points& x, int* triangle);
/// Inward unit normal at a surface point: area-weighted normals of the outer triangles within
/// `radius` of it (at least the triangle holding it).
Vec3 inwardNormal(const Model& model, const Points& x, const Vec3& site, int triangle,
                  double radius);
/// Probe centre at first contact when the sphere approaches along `axis` towards `site`
/// (sphere tracing against the outer surface).
Vec3 firstContactCenter(const Model& model, const Points& x, const Vec3& site, const Vec3& axis,
                        double radius);

/// The rest position of the material point at `site`, a point of the outer triangle `triangle`
/// in the state x (barycentric transfer).
Vec3 restPositionOf(const Model& model, const Points& x, const Vec3& site, int triangle);

class Indentation {
 public:
  Indentation(Model& model, IndentationSettings settings, SolverOptions solverOptions = {});

  /// Solves the turgid rest state (continuation in pressure if needed) and places the probe.
  /// `start`, when given, is a guess of the turgid state (e.g. a coarser tissue's turgid state
  /// carried onto this one): Newton starts there, and falls back to continuation from rest.
  SolveReport prepare(const Points* start = nullptr);
  bool prepared() const { return prepared_; }
  /// Back to the state prepare() left: the turgid rest state, the probe touching it, no load
  /// history (no solve: a prepared site that was pushed, as for an error estimate, is reused).
  void returnToFirstContact();

  /// Displacement control: moves the probe to `depth` and solves (warm start, sub-steps).
  CurvePoint goToDepth(double depth);
  /// Force control: applies `force` with the probe travel as an unknown.
  CurvePoint applyForce(double force);
  /// Straight to `target` (a depth, or a force under force control) from a guess of the state
  /// and of the probe's travel, e.g. an equilibrium of another mesh of the tissue carried over.
  /// A guess that does not converge leaves everything as it was (the point is not converged).
  CurvePoint solveFrom(double target, bool forceControl, Points guess, double travel);

  /// Called with each point of a run as it is solved, and how many of how many are done.
  using PointCallback = std::function<void(const CurvePoint&, int done, int total)>;
  /// The whole schedule from depth 0 (where a drag may have left the probe, it goes back first).
  /// `cancel` is checked at every Newton iteration: a cancelled run ends with the points done,
  /// the last state kept.
  std::vector<CurvePoint> run(const PointCallback& onPoint = {},
                              const std::atomic<bool>* cancel = nullptr);

  const Points& turgidState() const { return turgid_; }
  const Points& state() const { return x_; }
  double depth() const { return depth_; }
  const ProbePlacement& placement() const { return placement_; }
  const std::string& lastMessage() const { return message_; }
  const IndentationSettings& settings() const { return settings_; }
  /// Takes the schedule (control, maximum depth and force, steps, unloading) of `s`; the probe
  /// and the site stay as prepared.
  void setSchedule(const IndentationSettings& s);
  Model& model() { return model_; }
  EquilibriumSolver& solver() { return *solver_; }

 private:
  // Equilibrium under the probe force `force` (µN) from x, the probe's travel starting at and
  // returned in `travel` (µm); x and travel are left as given on failure.
  SolveReport solveUnderForce(Points& x, double force, double& travel);
  bool solveAt(double target, bool forceControl, int& iterations, double& residual);
  /// The tangent response u (3V) of the state x_ to a unit point load along the axis at the
  /// probe's point, and how far that point moves along the axis (µm per µN). False when the
  /// solver has no tangent to offer.
  bool siteResponse(Eigen::VectorXd& u, double& along);
  void remember();  // pushes the current equilibrium onto the predictor's history
  CurvePoint advance(double target, bool forceControl);
  double probeForce() const;

  Model& model_;
  IndentationSettings settings_;
  std::unique_ptr<EquilibriumSolver> solver_;
  bool prepared_ = false;
  Points turgid_, x_;
  double depth_ = 0;       // probe travel (µm) of the current equilibrium x_
  double load_ = 0;        // its control value (depth or force)
  bool forceMode_ = false;  // which control load_ and the history are in
  struct Equilibrium {
    double load, depth;
    Points x;
  };
  std::deque<Equilibrium> history_;  // the last (up to three) equilibria, for the predictor
  ProbePlacement placement_;
  std::string message_;
};

}  // namespace tp
