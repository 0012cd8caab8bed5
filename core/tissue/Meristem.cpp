#include "tissue/Meristem.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <unordered_map>

namespace tp {

using std::numbers::pi;

double DomeShape::volume() const {
  return pi * radius * radius * stemHeight + 2.0 / 3.0 * pi * radius * radius * capHeight;
}

namespace {

// Area density of the ellipsoidal cap per unit polar angle θ (per 2π in azimuth).
double capDensity(const DomeShape& s, double th) {
  return s.radius * std::sin(th) *
         std::sqrt(std::pow(s.capHeight * std::sin(th), 2) + std::pow(s.radius * std::cos(th), 2));
}

}  // namespace

double DomeShape::area() const {
  const int m = 2000;  // Simpson's rule on θ ∈ [0, π/2]
  const double hstep = 0.5 * pi / m;
  double sum = capDensity(*this, 0) + capDensity(*this, 0.5 * pi);
  for (int i = 1; i < m; ++i) sum += (i % 2 ? 4 : 2) * capDensity(*this, i * hstep);
  return 2 * pi * radius * stemHeight + 2 * pi * sum * hstep / 3;
}

bool DomeShape::contains(const Vec3& p) const {
  const double z = p.z();
  if (z < 0 || z > height()) return false;
  const double rho = std::hypot(p.x(), p.y());
  if (z <= stemHeight) return rho <= radius;
  const double t = (z - stemHeight) / capHeight;
  return rho <= radius * std::sqrt(std::max(0.0, 1 - t * t));
}

Vec3 DomeShape::closestPoint(const Vec3& p, Vec3* normal) const {
  const double rho = std::hypot(p.x(), p.y());
  const double phi = rho > 0 ? std::atan2(p.y(), p.x()) : 0.0;
  const double z = p.z();
  // In the meridian plane (ρ, z): the stem segment and the elliptic arc (R sin θ, zs + H cos θ).
  double bestRho = radius, bestZ = std::clamp(z, 0.0, stemHeight);
  double nRho = 1, nZ = 0;
  double best = std::hypot(rho - bestRho, z - bestZ);
  auto arc = [&](double th) {
    return std::hypot(radius * std::sin(th) - rho, stemHeight + capHeight * std::cos(th) - z);
  };
  int kBest = 0;
  const int samples = 48;
  double dBest = 1e300;
  for (int k = 0; k <= samples; ++k) {
    const double d = arc(0.5 * pi * k / samples);
    if (d < dBest) dBest = d, kBest = k;
  }
  // Golden-section refinement in the bracketing interval.
  double a = 0.5 * pi * std::max(0, kBest - 1) / samples;
  double b = 0.5 * pi * std::min(samples, kBest + 1) / samples;
  const double g = 0.5 * (std::sqrt(5.0) - 1);
  for (int it = 0; it < 45; ++it) {
    const double c = b - g * (b - a), d = a + g * (b - a);
    if (arc(c) < arc(d)) b = d;
    else a = c;
  }
  const double th = 0.5 * (a + b);
  if (arc(th) < best) {
    best = arc(th);
    bestRho = radius * std::sin(th);
    bestZ = stemHeight + capHeight * std::cos(th);
    nRho = std::sin(th) / radius;
    nZ = std::cos(th) / capHeight;
    const double len = std::hypot(nRho, nZ);
    nRho /= len;
    nZ /= len;
  }
  if (normal) *normal = Vec3(nRho * std::cos(phi), nRho * std::sin(phi), nZ);
  return Vec3(bestRho * std::cos(phi), bestRho * std::sin(phi), bestZ);
}

double DomeShape::depth(const Vec3& p) const {
  const double d = (closestPoint(p) - p).norm();
  return contains(p) ? d : -d;
}

namespace {

// Points at least `spacing` apart, by dart throwing, looked up in a hash grid.
class PoissonSet {
 public:
  explicit PoissonSet(double spacing) : s_(spacing) {}
  bool farFromAll(const Vec3& p) const {
    const auto c = cellOf(p);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = grid_.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
          if (it == grid_.end()) continue;
          for (int i : it->second)
            if ((points_[i] - p).norm() < s_) return false;
        }
    return true;
  }
  void add(const Vec3& p) {
    const auto c = cellOf(p);
    grid_[key(c[0], c[1], c[2])].push_back(static_cast<int>(points_.size()));
    points_.push_back(p);
  }
  const std::vector<Vec3>& points() const { return points_; }

 private:
  std::array<long long, 3> cellOf(const Vec3& p) const {
    return {static_cast<long long>(std::floor(p.x() / s_)),
            static_cast<long long>(std::floor(p.y() / s_)),
            static_cast<long long>(std::floor(p.z() / s_))};
  }
  static long long key(long long x, long long y, long long z) {
    return (x * 73856093LL) ^ (y * 19349663LL) ^ (z * 83492791LL);
  }
  double s_;
  std::vector<Vec3> points_;
  std::unordered_map<long long, std::vector<int>> grid_;
};

// Uniform random points on the lateral surface and the cap (inverse CDF in θ for the cap).
class SurfaceSampler {
 public:
  explicit SurfaceSampler(const DomeShape& s) : s_(s) {
    const int m = 4096;
    cdf_.resize(m + 1, 0.0);
    for (int i = 1; i <= m; ++i) {
      const double th = 0.5 * pi * (i - 0.5) / m;
      cdf_[i] = cdf_[i - 1] + capDensity(s, th);
    }
    capArea_ = 2 * pi * cdf_.back() * 0.5 * pi / m;
    stemArea_ = 2 * pi * s.radius * s.stemHeight;
  }
  Vec3 sample(std::mt19937& rng, Vec3* normal) const {
    std::uniform_real_distribution<double> u(0, 1);
    const double phi = 2 * pi * u(rng);
    if (u(rng) * (capArea_ + stemArea_) < stemArea_) {
      *normal = Vec3(std::cos(phi), std::sin(phi), 0);
      return Vec3(s_.radius * std::cos(phi), s_.radius * std::sin(phi), s_.stemHeight * u(rng));
    }
    const double target = u(rng) * cdf_.back();
    const auto it = std::lower_bound(cdf_.begin(), cdf_.end(), target);
    const int i = std::max(1, static_cast<int>(it - cdf_.begin()));
    const double frac = (target - cdf_[i - 1]) / std::max(1e-300, cdf_[i] - cdf_[i - 1]);
    const double th = 0.5 * pi * (i - 1 + frac) / (cdf_.size() - 1);
    const double r = s_.radius * std::sin(th);
    Vec3 n(std::sin(th) / s_.radius, 0, std::cos(th) / s_.capHeight);
    n.normalize();
    *normal = Vec3(n.x() * std::cos(phi), n.x() * std::sin(phi), n.z());
    return Vec3(r * std::cos(phi), r * std::sin(phi), s_.stemHeight + s_.capHeight * std::cos(th));
  }
  double area() const { return capArea_ + stemArea_; }

 private:
  const DomeShape& s_;
  std::vector<double> cdf_;
  double capArea_ = 0, stemArea_ = 0;
};

struct Seeds {
  std::vector<Vec3> points;
  std::vector<int> layer;  // 1 = L1, 2 = L2, 0 = inner
  int l1 = 0, l2 = 0, inner = 0;
  double spacing = 0;
};

Seeds placeSeeds(const MeristemParams& prm, double s) {
  const DomeShape& shape = prm.shape;
  std::mt19937 rng(prm.seed);
  SurfaceSampler sampler(shape);
  Seeds out;
  const double t1 = prm.l1Thickness, t2 = prm.l2Thickness;
  // One layer: dart throwing on the surface, each point pushed in along the normal.
  auto layer = [&](double depth) {
    PoissonSet set(s);
    std::vector<Vec3> seeds;
    const int maxMisses = 4000;
    for (int misses = 0; misses < maxMisses;) {
      Vec3 n;
      const Vec3 p = sampler.sample(rng, &n);
      if (!set.farFromAll(p)) {
        ++misses;
        continue;
      }
      const Vec3 seed = p - depth * n;
      if (seed.z() <= 0.25 * depth || shape.depth(seed) < 0.5 * depth) {  // near the base rim
        ++misses;
        continue;
      }
      set.add(p);
      seeds.push_back(seed);
      misses = 0;
    }
    return seeds;
  };
  const auto l1 = layer(0.5 * t1);
  const auto l2 = layer(t1 + 0.5 * t2);
  out.points = l1;
  out.points.insert(out.points.end(), l2.begin(), l2.end());
  out.l1 = static_cast<int>(l1.size());
  out.l2 = static_cast<int>(l2.size());
  out.layer.assign(out.l1, 1);
  out.layer.insert(out.layer.end(), out.l2, 2);
  // Inner cells: dart throwing in the volume below the two layers.
  PoissonSet inner(s);
  for (const auto& p : l2) inner.add(p);
  std::uniform_real_distribution<double> ux(-shape.radius, shape.radius), uz(0, shape.height());
  const double minDepth = t1 + t2 + 0.25 * s;
  for (int misses = 0; misses < 20000;) {
    const Vec3 p(ux(rng), ux(rng), uz(rng));
    if (p.z() < 0.3 * s || !shape.contains(p) || !inner.farFromAll(p) || shape.depth(p) < minDepth) {
      ++misses;
      continue;
    }
    inner.add(p);
    out.points.push_back(p);
    out.layer.push_back(0);
    ++out.inner;
    misses = 0;
  }
  return out;
}

// Mirror images of the seeds near the boundary: across the tangent plane at their foot point on
// the surface, and across the base plane.
void makeGhosts(const DomeShape& shape, const std::vector<Vec3>& seeds, double spacing,
                std::vector<Vec3>& ghosts, std::vector<BoundaryKind>& kinds) {
  ghosts.clear();
  kinds.clear();
  for (const auto& p : seeds) {
    if (shape.depth(p) < 1.5 * spacing) {
      ghosts.push_back(2 * shape.closestPoint(p) - p);
      kinds.push_back(BoundaryKind::Surface);
    }
    if (p.z() < 1.5 * spacing) {
      ghosts.emplace_back(p.x(), p.y(), -p.z());
      kinds.push_back(BoundaryKind::Base);
    }
  }
}

// Lloyd relaxation towards a centroidal Voronoi tessellation, keeping the layers: L1 and L2
// seeds move along their offset surfaces, inner seeds stay below the two layers.
void relax(const MeristemParams& prm, Seeds& seeds, int iterations) {
  const DomeShape& shape = prm.shape;
  const double t1 = prm.l1Thickness, t2 = prm.l2Thickness, s = seeds.spacing;
  std::vector<Vec3> ghosts, centroids;
  std::vector<BoundaryKind> kinds;
  std::vector<double> volumes;
  for (int it = 0; it < iterations; ++it) {
    makeGhosts(shape, seeds.points, s, ghosts, kinds);
    voronoiCentroids(seeds.points, ghosts, centroids, volumes);
    for (size_t i = 0; i < seeds.points.size(); ++i) {
      Vec3 n;
      const Vec3 c = centroids[i];
      const Vec3 foot = shape.closestPoint(c, &n);
      Vec3 p = c;
      if (seeds.layer[i] == 1) p = foot - 0.5 * t1 * n;
      else if (seeds.layer[i] == 2) p = foot - (t1 + 0.5 * t2) * n;
      else if (shape.depth(c) < t1 + t2 + 0.25 * s) p = foot - (t1 + t2 + 0.25 * s) * n;
      p.z() = std::max(p.z(), 0.1 * s);
      seeds.points[i] = p;
    }
  }
}

}  // namespace

CellComplex generateMeristem(const MeristemParams& prm, MeristemReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  const DomeShape& shape = prm.shape;
  if (!(shape.radius > 0 && shape.capHeight > 0 && shape.stemHeight >= 0))
    throw std::invalid_argument("the dome needs a positive radius and cap height");
  if (!(std::isfinite(shape.radius) && std::isfinite(shape.capHeight) &&
        std::isfinite(shape.stemHeight) && shape.radius <= 1e4 && shape.capHeight <= 1e4 &&
        shape.stemHeight <= 1e4))
    throw std::invalid_argument("the dome's sizes must be finite and at most 10000 µm");
  // About 5 vertices and 20 triangles a cell: 20,000 cells is ~100k vertices, ~1.5 GB to solve
  // on 2 cores (bench/README.md); more is refused, not attempted.
  if (prm.cells < 10 || prm.cells > kMaxCells)
    throw std::invalid_argument("a meristem has between 10 and " + std::to_string(kMaxCells) +
                                " cells (asked for " + std::to_string(prm.cells) + ")");
  if (!(prm.l1Thickness > 0 && prm.l2Thickness > 0) ||
      prm.l1Thickness + prm.l2Thickness >= std::min(shape.radius, shape.height()))
    throw std::invalid_argument("the L1 and L2 layers do not fit in the dome");

  // The seed spacing that gives the requested number of cells. The count goes roughly as
  // spacing^-2.5 (two surface layers and a volume), so iterate s ← s (count/target)^(1/2.5).
  double spacing = std::cbrt(0.7 * shape.volume() / prm.cells);
  Seeds seeds;
  Seeds best;
  for (int it = 0; it < 12; ++it) {
    seeds = placeSeeds(prm, spacing);
    const int count = static_cast<int>(seeds.points.size());
    if (best.points.empty() || std::abs(count - prm.cells) <
                                   std::abs(static_cast<int>(best.points.size()) - prm.cells)) {
      best = seeds;
      best.spacing = spacing;
    }
    if (std::abs(count - prm.cells) <= std::max(2, prm.cells / 50)) break;
    spacing *= std::pow(static_cast<double>(std::max(count, 1)) / prm.cells, 1 / 2.5);
  }
  seeds = best;
  spacing = best.spacing;
  relax(prm, seeds, prm.relaxIterations);

  std::vector<Vec3> ghosts;
  std::vector<BoundaryKind> kinds;
  makeGhosts(shape, seeds.points, spacing, ghosts, kinds);
  VoronoiOptions vo;
  vo.collapseLength = prm.collapseFraction * spacing;
  vo.projectToSurface = [&shape](const Vec3& p) { return shape.closestPoint(p); };
  vo.baseZ = 0;
  VoronoiReport vr;
  CellComplex cc = buildVoronoiTissue(seeds.points, {}, ghosts, kinds, vo, &vr);
  const ValidityReport valid = checkValidity(cc);
  if (!valid.ok() && prm.requireValid)
    throw std::runtime_error("the generated tissue is not valid (seed " +
                             std::to_string(prm.seed) + "): " + valid.summary());
  if (report) {
    report->cells = cc.cellCount();
    report->l1Cells = seeds.l1;
    report->l2Cells = seeds.l2;
    report->innerCells = seeds.inner;
    report->cellSpacing = spacing;
    report->voronoi = vr;
    report->validity = valid;
    report->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  return cc;
}

}  // namespace tp
