#pragma once
// Force–depth curves as the window keeps them: each with a name (site and parameters), the site
// and parameters it was computed with and its points; several curves in one CSV file (long
// format), and the nondimensional axes [I] = I/L, [F] = F/(E L²). Units: µm, µN, MPa.

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "Parameters.h"
#include "experiment/Indentation.h"

namespace tp::gui {

struct NamedCurve {
  std::string name;
  Eigen::Vector3d site = Eigen::Vector3d::Zero();  // µm, on the turgid surface
  SimulationParams params;
  std::vector<CurvePoint> points;
  bool live = false;  // grown by dragging the probe (not a scheduled run)
  bool measured = false;  // read from an experiment's file: drawn as points, not simulated
  // A fit's curve: measured − simulated force (µN) at each of its points (empty otherwise).
  std::vector<double> residuals;
  // The mesh it was computed on and the estimated discretisation error of its deepest point.
  int meshLevel = -1;       // -1: not known
  double meshError = -1;    // relative; < 0: not estimated (yet)
  double meshErrorAt = 0;   // µm (or µN when meshErrorForce)
  bool meshErrorForce = false;
  std::string meshErrorMethod;
  int preparation = -1;     // the worker's preparation it belongs to (not saved)
  int colour = -1;          // its colour in the plot's palette, for its whole life (not saved)
};

/// A probe force (µN) for the screen: four significant digits, and "0" below a piconewton
/// (1e-6 µN), a hundredth of what an AFM resolves: at first contact the force is the penalty's
/// round-off, e.g. 1.6e-8 µN, which is not a measurement.
std::string forceText(double force);

/// "±1.2 %" (or "error not estimated"), for legends and lists.
std::string meshErrorText(const NamedCurve& c);

/// The name of a curve: "site 2 (0.0, 0.0, 45.8) µm · E 100 MPa, p 0.8 MPa, r 1 µm".
std::string curveName(int siteNumber, const Eigen::Vector3d& site, const SimulationParams& p,
                      bool live);

/// Long-format CSV, one row per point of every curve:
///   curve,site_x_um,site_y_um,site_z_um,E_MPa,nu,h_um,p_MPa,probe_radius_um,mesh_level,
///   mesh_error,depth_um,force_uN,iterations,residual,converged,unloading
/// after one `#` comment line per curve naming its mesh and estimated discretisation error.
/// The curve name is quoted ("" for a quote inside); the site and parameters repeat on each of
/// its rows (empty for a measured curve); numbers as tp::curveCsv writes them.
std::string curvesCsv(const std::vector<NamedCurve>& curves);
/// Writes curvesCsv atomically; throws std::runtime_error if writing fails.
void writeCurvesCsv(const std::string& path, const std::vector<NamedCurve>& curves);
/// Reads the long format back (also without the curve columns, as earlier versions wrote it):
/// (name, points) in the order the curves first appear. Throws
/// std::runtime_error naming `nameForErrors` and the line.
std::vector<std::pair<std::string, std::vector<CurvePoint>>> parseCurvesCsv(
    std::string_view text, const std::string& nameForErrors);

/// Scales for the plot axes: depth × depthScale, force × forceScale.
struct AxisScale {
  double depth = 1, force = 1;
};
/// Real units (1, 1) or nondimensional (1/L, 1/(E L²)) with L the mean cell size (µm) and E the
/// curve's Young's modulus (MPa): E L² is a force in µN.
AxisScale axisScale(bool nondimensional, double meanCellSize, double youngModulus);

}  // namespace tp::gui
