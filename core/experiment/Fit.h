#pragma once
// Reading measured force–indentation curves through the model: the wall's Young modulus E, the
// turgor p and the wall thickness h (any subset), and each curve's contact-point offset, fitted
// by least squares between simulated and measured forces at the measured depths
// (Levenberg–Marquardt, Ceres Solver). The simulated force's derivatives are exact
// (experiment/Sensitivity.h: implicit differentiation of each equilibrium), not finite
// differences of curves. Reported: the values with standard errors and 95 % intervals from the
// Jacobian (normal approximation, σ² from the residual), their correlations, the residual, and
// whether E and p can be told apart from these curves, with what would separate them.
// Units: µm, µN, MPa.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "experiment/Experiment.h"
#include "io/MeasuredCurve.h"

namespace tp {

struct FitCurve {
  MeasuredCurve data;              // depth from the contact point (µm), force (µN)
  std::optional<Vec3> site;        // µm, near the tissue's surface; default: the site (or the
                                   // material point) of FitSettings::start, else the top
  std::optional<double> pressure;  // turgor held for this curve (0: plasmolysed); default: p
};

struct FitSettings {
  // Material, pressure (the starting values), probe, mesh, solver. The axis is held during the
  // fit: as given, else the inward normal at the site in the starting values' turgid state.
  ExperimentSettings start;
  bool fitE = true, fitP = true, fitH = false;
  bool fitOffset = false;  // a contact-point offset per curve (µm, added to the model's depth)
  int maxIterations = 30;
  // Measured points compared per curve, evenly spread over its depths (their number costs
  // nothing beyond the simulated depths below: it is the residual's length).
  int maxPoints = 200;
  // Depths simulated per curve, evenly spread over its points' depths; the force at the points
  // between them, and its derivatives, are the cubic spline through the simulated ones
  // (Fit.cpp). 0: every point is simulated.
  int simulatedDepths = 10;
  // With E and p both fitted (and any held turgor 0), search over p/E with E in closed form
  // (variable projection, Fit.cpp); off: over E and p together, as a check of the former.
  bool factorOutModulus = true;
};

struct FitValue {
  std::string key;   // "E", "p", "h", "offset_1", ...
  std::string unit;  // "MPa", "um"
  double value = 0;
  double error = 0;  // standard error (1 sigma); 0 when held
  bool fitted = false;
};

struct FitResult {
  bool converged = false;
  std::string message;  // Ceres' summary line, or why it failed
  int iterations = 0;
  int evaluations = 0;                  // simulations of every curve (a θ asked again is not)
  std::vector<FitValue> values;         // E, p, h, then one offset per curve
  std::vector<std::string> fittedKeys;  // the rows and columns of `correlation`
  Eigen::MatrixXd correlation;
  double rms = 0;            // µN, root mean square residual at the fit
  double rmsStart = 0;       // at the starting values
  bool identifiable = true;  // every fitted value determined (see advice)
  std::string advice;        // when not: why, and what would separate them
  struct Curve {
    std::vector<double> depth, measured, simulated;  // the points used (µm, µN, µN)
    double hertzModulus = 0;  // the measured curve's Hertz apparent modulus (MPa)
    int simulatedDepths = 0;  // the depths simulated at the fit (FitSettings::simulatedDepths)
    int meshLevel = 0;
    MeshError meshError;  // of the simulated end force at the fitted values (automatic mesh)
  };
  std::vector<Curve> curves;
  const FitValue* find(const std::string& key) const;
};

/// The weights W (points × nodes) of the cubic spline through values at the increasing nodes t,
/// at the points x: s(x_i) = Σ_j W_ij y_j (not-a-knot ends; the parabola through three nodes,
/// the line through two). A fit interpolates each curve's simulated forces and their
/// derivatives with it, so the derivatives at the points are exactly those of the forces there.
Eigen::MatrixXd splineWeights(const std::vector<double>& t, const std::vector<double>& x);

/// Fits `settings` to the curves on `tissue`. With the automatic mesh the search starts on its
/// first level and each curve's mesh error is then estimated at the fitted values; a curve whose
/// error is above the tolerance there is refined (Experiment::run from the next level) and the
/// search resumed from the fitted values, until none is. A simulation that fails during the search is a
/// step Ceres rejects; failing at the start, or a cancel, throws (SolveFailure, Cancelled).
/// Throws std::invalid_argument for nothing to fit or a curve without a positive depth.
FitResult fitCurves(std::shared_ptr<const CellComplex> tissue, const FitSettings& settings,
                    const std::vector<FitCurve>& curves, const Monitor& monitor = {});

}  // namespace tp
