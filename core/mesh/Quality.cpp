#include "mesh/Quality.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

namespace tp {

MeshQuality measureQuality(const CellComplex& cc) {
  MeshQuality q;
  q.vertices = cc.vertexCount();
  q.triangles = cc.triangleCount();
  q.walls = cc.wallCount();
  q.cells = cc.cellCount();
  q.validity = checkValidity(cc);
  for (auto f : cc.fixed) q.clampedVertices += f ? 1 : 0;
  if (q.vertices > 0) {
    q.bboxMin = cc.rest.rowwise().minCoeff();
    q.bboxMax = cc.rest.rowwise().maxCoeff();
  }
  double minA = std::numeric_limits<double>::infinity(), maxA = 0;
  double edgeSum = 0, minEdge = std::numeric_limits<double>::infinity();
  int edgeCount = 0;
  for (int t = 0; t < q.triangles; ++t) {
    const auto& tri = cc.triangles[t];
    Vec3 p[3];
    for (int k = 0; k < 3; ++k) p[k] = cc.rest.col(tri[k]);
    for (int k = 0; k < 3; ++k) {
      const Vec3 u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
      const double ang = std::atan2(u.cross(v).norm(), u.dot(v)) * 180.0 / std::numbers::pi;
      minA = std::min(minA, ang);
      maxA = std::max(maxA, ang);
      edgeSum += u.norm();
      minEdge = std::min(minEdge, u.norm());
      ++edgeCount;
    }
    if (cc.isOuterTriangle(t)) {
      ++q.outerTriangles;
      q.outerArea += 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    }
  }
  if (edgeCount) {
    q.minAngleDeg = minA;
    q.maxAngleDeg = maxA;
    q.meanEdge = edgeSum / edgeCount;
    q.minEdge = minEdge;
  }
  for (double v : cellVolumes(cc, cc.rest)) q.volume += v;
  return q;
}

std::string simulationProblem(const CellComplex& cc) {
  if (cc.triangleCount() == 0) return "the tissue has no walls";
  const ValidityReport r = checkValidity(cc);
  if (!r.ok()) {
    std::string msg = "not a valid tissue: " + r.summary();
    if (r.openCells > 0 && r.openCells == cc.cellCount())
      msg += ". Every cell is open: this is a surface mesh (MorphoGraphX and openalea L1 meshes "
             "hold the outer walls only), not a 3D cell complex; build a tissue from the cells' "
             "centroids instead (tissueprobe-cli build --centroids FILE)";
    return msg;
  }
  bool anyFixed = false;
  for (auto f : cc.fixed) anyFixed = anyFixed || f != 0;
  if (!anyFixed)
    return "no vertex is clamped (the vertex property 'fixed'), so the tissue would move as a "
           "rigid body under the probe; clamp its base";
  return {};
}

std::string formatQuality(const MeshQuality& q) {
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "cells            %d\n"
                "walls            %d\n"
                "vertices         %d (%d clamped)\n"
                "triangles        %d (%d on the outer surface)\n"
                "closed           %s\n"
                "volume           %.6g um^3\n"
                "outer area       %.6g um^2\n"
                "bounding box     [%.4g, %.4g] x [%.4g, %.4g] x [%.4g, %.4g] um\n"
                "edge length      mean %.4g um, min %.4g um\n"
                "triangle angles  min %.2f deg, max %.2f deg\n",
                q.cells, q.walls, q.vertices, q.clampedVertices, q.triangles, q.outerTriangles,
                q.cells == 0      ? "no: a sheet (no cells)"
                : q.validity.ok() ? (q.validity.openCells ? "yes (open cells clamped at the rim)"
                                                          : "yes, every cell")
                                  : "NO",
                q.volume, q.outerArea, q.bboxMin.x(), q.bboxMax.x(), q.bboxMin.y(),
                q.bboxMax.y(), q.bboxMin.z(), q.bboxMax.z(), q.meanEdge, q.minEdge, q.minAngleDeg,
                q.maxAngleDeg);
  std::string s = buf;
  for (const auto& e : q.validity.errors) s += "error:   " + e + "\n";
  for (const auto& w : q.validity.warnings) s += "warning: " + w + "\n";
  return s;
}

}  // namespace tp
