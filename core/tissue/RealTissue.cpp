#include "tissue/RealTissue.h"

#include <CGAL/Alpha_shape_3.h>
#include <CGAL/Alpha_shape_cell_base_3.h>
#include <CGAL/Alpha_shape_vertex_base_3.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "mechanics/Contact.h"

namespace tp {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vbi = CGAL::Triangulation_vertex_base_with_info_3<int, K>;
using Vb = CGAL::Alpha_shape_vertex_base_3<K, Vbi>;
using Cb = CGAL::Alpha_shape_cell_base_3<K>;
using Tds = CGAL::Triangulation_data_structure_3<Vb, Cb>;
using Delaunay = CGAL::Delaunay_triangulation_3<K, Tds>;
using AlphaShape = CGAL::Alpha_shape_3<Delaunay>;

struct Surface {
  std::vector<Eigen::Vector3i> tris;  // indices into the centroid list, wound outward
  std::vector<Vec3> vertexNormal;     // per centroid (zero if not on the surface)
};

Surface alphaSurface(const std::vector<Vec3>& pts, double alphaFactor, double* alphaOut) {
  std::vector<std::pair<K::Point_3, int>> input;
  for (size_t i = 0; i < pts.size(); ++i)
    input.emplace_back(K::Point_3(pts[i].x(), pts[i].y(), pts[i].z()), static_cast<int>(i));
  Delaunay dt(input.begin(), input.end());
  // Coplanar or collinear centroids have no 3D triangulation, and CGAL's optimal-alpha search
  // on one is undefined behaviour (UBSan, issue 9): refuse them by name first.
  if (dt.dimension() < 3)
    throw std::invalid_argument("the centroids lie in a " +
                                std::string(dt.dimension() == 2 ? "plane" : "line or point") +
                                ": a 3D tissue needs centroids spread in all three directions");
  AlphaShape as(dt, 0, AlphaShape::REGULARIZED);
  const auto opt = as.find_optimal_alpha(1);
  if (opt == as.alpha_end()) throw std::runtime_error("no alpha shape encloses the centroids");
  const double alpha = *opt * alphaFactor;
  as.set_alpha(alpha);
  if (alphaOut) *alphaOut = alpha;
  std::vector<AlphaShape::Facet> facets;
  as.get_alpha_shape_facets(std::back_inserter(facets), AlphaShape::REGULAR);
  Surface s;
  s.vertexNormal.assign(pts.size(), Vec3::Zero());
  for (auto f : facets) {
    // Make f.first the interior cell; the facet's normal must point away from its apex.
    if (as.classify(f.first) != AlphaShape::INTERIOR) f = dt.mirror_facet(f);
    const int i = f.second;
    int v[3];
    for (int k = 0; k < 3; ++k) v[k] = f.first->vertex((i + 1 + k) % 4)->info();
    const Vec3 apex(f.first->vertex(i)->point().x(), f.first->vertex(i)->point().y(),
                    f.first->vertex(i)->point().z());
    Vec3 n = (pts[v[1]] - pts[v[0]]).cross(pts[v[2]] - pts[v[0]]);
    if (n.dot(pts[v[0]] - apex) < 0) {
      std::swap(v[1], v[2]);
      n = -n;
    }
    s.tris.emplace_back(v[0], v[1], v[2]);
    for (int k = 0; k < 3; ++k) s.vertexNormal[v[k]] += n;  // area-weighted
  }
  for (auto& n : s.vertexNormal)
    if (n.norm() > 0) n.normalize();
  return s;
}

double medianNearestNeighbour(const std::vector<Vec3>& pts) {
  std::vector<std::pair<K::Point_3, int>> input;
  for (size_t i = 0; i < pts.size(); ++i)
    input.emplace_back(K::Point_3(pts[i].x(), pts[i].y(), pts[i].z()), static_cast<int>(i));
  CGAL::Delaunay_triangulation_3<K, CGAL::Triangulation_data_structure_3<Vbi>> dt(input.begin(),
                                                                                  input.end());
  std::vector<double> nn(pts.size(), std::numeric_limits<double>::infinity());
  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
    const int a = e->first->vertex(e->second)->info(), b = e->first->vertex(e->third)->info();
    const double d = (pts[a] - pts[b]).norm();
    nn[a] = std::min(nn[a], d);
    nn[b] = std::min(nn[b], d);
  }
  std::nth_element(nn.begin(), nn.begin() + nn.size() / 2, nn.end());
  return nn[nn.size() / 2];
}

}  // namespace

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  const size_t n = std::min(a.size(), b.size());
  if (n < 2) return std::numeric_limits<double>::quiet_NaN();
  double ma = 0, mb = 0;
  for (size_t i = 0; i < n; ++i) ma += a[i], mb += b[i];
  ma /= n;
  mb /= n;
  double sab = 0, saa = 0, sbb = 0;
  for (size_t i = 0; i < n; ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

CellComplex tissueFromCentroids(const CentroidTable& table, const RealTissueOptions& opt,
                                RealTissueReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<Vec3>& all = table.points;
  if (all.size() < 4) throw std::invalid_argument("a tissue needs at least 4 centroids");
  RealTissueReport rep;
  rep.cellSize = opt.cellSize > 0 ? opt.cellSize : 1.1 * medianNearestNeighbour(all);
  if (!(rep.cellSize > 0)) throw std::invalid_argument("centroids coincide: no cell size");
  const double offset = opt.offset >= 0 ? opt.offset : 0.5 * rep.cellSize;
  double zmin = all[0].z();
  for (const auto& p : all) zmin = std::min(zmin, p.z());
  if (opt.baseZ && !std::isfinite(*opt.baseZ))
    throw std::invalid_argument("the base plane z must be a finite number (got " +
                                std::to_string(*opt.baseZ) + ")");
  rep.baseZ = opt.baseZ ? *opt.baseZ : zmin + rep.cellSize;

  // The closing surface is reconstructed from every centroid, then the base plane cuts it.
  // A CGAL precondition that still fails (centroids nearly degenerate at a scale the checks
  // above let through) is the input's fault: reported as such, never a crash.
  Surface surf;
  try {
    surf = alphaSurface(all, opt.alphaFactor, &rep.alpha);
  } catch (const CGAL::Failure_exception& e) {
    throw std::invalid_argument("the surface around the centroids cannot be reconstructed "
                                "(CGAL: " + e.expression() + " failed): are they nearly "
                                "coplanar or collinear?");
  }
  rep.surfaceTriangles = static_cast<int>(surf.tris.size());

  std::vector<Vec3> seeds;
  std::vector<int> labels;
  for (size_t i = 0; i < all.size(); ++i) {
    if (all[i].z() <= rep.baseZ) {
      ++rep.droppedBelowBase;
      continue;
    }
    seeds.push_back(all[i]);
    labels.push_back(table.labels[i]);
    rep.keptRows.push_back(static_cast<int>(i));
  }
  if (seeds.size() < 4) throw std::invalid_argument("fewer than 4 centroids above the base plane");

  // Ghosts: each seed near the surface mirrored across the tangent plane of the surface pushed
  // out by `offset`; each seed near the base mirrored across the base.
  std::vector<Vec3> ghosts;
  std::vector<BoundaryKind> kinds;
  for (size_t k = 0; k < seeds.size(); ++k) {
    const Vec3& p = seeds[k];
    double best = std::numeric_limits<double>::infinity();
    Vec3 foot = p;
    for (const auto& t : surf.tris) {
      Vec3 y;
      const double d2 = pointTriangleDistance2(p, all[t[0]], all[t[1]], all[t[2]], nullptr,
                                               nullptr, nullptr, &y);
      if (d2 < best) best = d2, foot = y;
    }
    const double d = std::sqrt(best);
    if (d < 2.0 * rep.cellSize) {
      Vec3 n = d > 1e-9 * rep.cellSize ? Vec3((foot - p) / d) : surf.vertexNormal[rep.keptRows[k]];
      if (n.norm() == 0) continue;
      ghosts.push_back(p + 2.0 * (d + offset) * n);
      kinds.push_back(BoundaryKind::Surface);
    }
    if (p.z() - rep.baseZ < 2.0 * rep.cellSize) {
      ghosts.emplace_back(p.x(), p.y(), 2.0 * rep.baseZ - p.z());
      kinds.push_back(BoundaryKind::Base);
    }
  }
  VoronoiOptions vo;
  vo.collapseLength = opt.collapseFraction * rep.cellSize;
  vo.baseZ = rep.baseZ;
  CellComplex cc = buildVoronoiTissue(seeds, labels, ghosts, kinds, vo, &rep.voronoi);
  rep.validity = checkValidity(cc);
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (report) *report = rep;
  return cc;
}

}  // namespace tp
