#include "mechanics/Assembly.h"

#include <omp.h>

#include <algorithm>
#include <stdexcept>

namespace tp {

DofMap::DofMap(const std::vector<std::uint8_t>& fixedDof) : index_(fixedDof.size(), -1) {
  for (size_t i = 0; i < fixedDof.size(); ++i)
    if (!fixedDof[i]) {
      index_[i] = static_cast<int>(free_.size());
      free_.push_back(static_cast<int>(i));
    }
}

int SparsePattern::find(int row, int col) const {
  const auto first = rowIdx.begin() + colPtr[col];
  const auto last = rowIdx.begin() + colPtr[col + 1];
  const auto it = std::lower_bound(first, last, row);
  if (it == last || *it != row) return -1;
  return static_cast<int>(it - rowIdx.begin());
}

void symmetricMultiply(const SparsePattern& pattern, const std::vector<double>& values,
                       const double* v, double* y) {
  // Columns [j0, j1) of the upper triangle, accumulated into out: each stored a_ij adds
  // a_ij v_j to row i and, off the diagonal, a_ij v_i to row j.
  const auto columns = [&](int j0, int j1, double* out) {
    for (int j = j0; j < j1; ++j) {
      const double vj = v[j];
      double acc = 0;
      for (int k = pattern.colPtr[j]; k < pattern.colPtr[j + 1]; ++k) {
        const int i = pattern.rowIdx[k];
        const double a = values[k];
        acc += a * v[i];
        if (i != j) out[i] += a * vj;
      }
      out[j] += acc;
    }
  };
  std::fill(y, y + pattern.n, 0.0);
  // Two threads when there are two and the matrix is large enough to pay for them: each takes
  // half of the nonzeros; the second accumulates into its own vector, added at the end.
  if (pattern.nnz() < 200000 || omp_get_max_threads() < 2 || omp_in_parallel()) {
    columns(0, pattern.n, y);
    return;
  }
  const int half = static_cast<int>(
      std::lower_bound(pattern.colPtr.begin(), pattern.colPtr.end(), pattern.nnz() / 2) -
      pattern.colPtr.begin());
  std::vector<double> second(pattern.n, 0.0);
#pragma omp parallel num_threads(2)
  {
    if (omp_get_thread_num() == 0)
      columns(0, std::min(half, pattern.n), y);
    else
      columns(std::min(half, pattern.n), pattern.n, second.data());
  }
  for (int i = 0; i < pattern.n; ++i) y[i] += second[i];
}

SparsePattern buildPattern(const DofMap& dofs, int vertexCount,
                           const std::vector<std::pair<int, std::span<const int>>>& elementSets) {
  // Vertex adjacency: for each vertex b, the vertices a ≤ b sharing an element with it.
  std::vector<std::vector<int>> lower(vertexCount);
  for (int b = 0; b < vertexCount; ++b) lower[b].push_back(b);
  for (const auto& [arity, verts] : elementSets) {
    const size_t count = verts.size() / arity;
    for (size_t e = 0; e < count; ++e) {
      const int* v = verts.data() + e * arity;
      for (int i = 0; i < arity; ++i)
        for (int j = 0; j < arity; ++j)
          if (v[i] < v[j]) lower[v[j]].push_back(v[i]);
    }
  }
  SparsePattern p;
  p.n = dofs.freeCount();
  p.colPtr.assign(p.n + 1, 0);
  for (auto& l : lower) {
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
  }
  // Free unknowns are numbered in the order of the full components, so for a ≤ b every free
  // component of a precedes those of b, and rows come out sorted.
  for (int b = 0; b < vertexCount; ++b) {
    for (int cb = 0; cb < 3; ++cb) {
      const int col = dofs.index(3 * b + cb);
      if (col < 0) continue;
      for (int a : lower[b])
        for (int ca = 0; ca < 3; ++ca) {
          const int row = dofs.index(3 * a + ca);
          if (row < 0 || row > col) continue;
          p.rowIdx.push_back(row);
        }
      p.colPtr[col + 1] = static_cast<int>(p.rowIdx.size());
    }
  }
  return p;
}

namespace {

// Which elements hold each unknown: elements given as lists of unknowns (the list of element e
// is flat[begin[e], begin[e+1]), −1: none); for unknown c, the entries inc[start[c], start[c+1])
// are the positions k in flat with flat[k] == c (a counting sort), and elementOf[k] is the
// element position k belongs to.
struct Incidence {
  std::vector<int> start, inc, elementOf;
  Incidence(int n, std::span<const int> flat, std::span<const int> begin)
      : start(n + 2, 0), elementOf(flat.size()) {
    for (size_t e = 0; e + 1 < begin.size(); ++e)
      std::fill(elementOf.begin() + begin[e], elementOf.begin() + begin[e + 1], static_cast<int>(e));
    for (int a : flat)
      if (a >= 0) ++start[a + 2];
    for (int c = 0; c < n; ++c) start[c + 2] += start[c + 1];
    inc.resize(start[n + 1]);
    for (int k = 0; k < static_cast<int>(flat.size()); ++k)
      if (flat[k] >= 0) inc[start[flat[k] + 1]++] = k;
  }
};

// Index of the local entry (i, j), i ≤ j, of an m-unknown element in its upper triangle stored
// row by row.
inline int upperIndex(int i, int j, int m) { return i * m - i * (i - 1) / 2 + (j - i); }

}  // namespace

// Column by column: the rows ≤ c of every element holding c, deduplicated with a marker array
// and sorted. The elements are visited through their incidence, so the work is the number of
// element entries (a vector per column filled by push_back cost 0.18 s for the 1.7M entries of
// the real flower at level 3, more than the factorisation's symbolic analysis).
SparsePattern buildPatternFromUnknowns(int n, const std::vector<std::span<const int>>& elements) {
  std::vector<int> flat, begin{0};
  for (const auto& u : elements) {
    flat.insert(flat.end(), u.begin(), u.end());
    begin.push_back(static_cast<int>(flat.size()));
  }
  const Incidence incidence(n, flat, begin);
  SparsePattern p;
  p.n = n;
  p.colPtr.assign(n + 1, 0);
  std::vector<int> mark(n, -1), rows;
  for (int c = 0; c < n; ++c) {
    rows.assign(1, c);
    mark[c] = c;
    for (int q = incidence.start[c]; q < incidence.start[c + 1]; ++q) {
      const int e = incidence.elementOf[incidence.inc[q]];
      for (int k = begin[e]; k < begin[e + 1]; ++k) {
        const int a = flat[k];
        if (a >= 0 && a < c && mark[a] != c) {
          mark[a] = c;
          rows.push_back(a);
        }
      }
    }
    std::sort(rows.begin(), rows.end());
    p.rowIdx.insert(p.rowIdx.end(), rows.begin(), rows.end());
    p.colPtr[c + 1] = static_cast<int>(p.rowIdx.size());
  }
  return p;
}

void elementPositions(const SparsePattern& pattern, std::span<const int> unknowns,
                      std::span<const int> begin, std::vector<int>& slotBegin,
                      std::vector<int>& positions) {
  const int E = static_cast<int>(begin.size()) - 1;
  slotBegin.assign(E + 1, 0);
  for (int e = 0; e < E; ++e) {
    const int m = begin[e + 1] - begin[e];
    slotBegin[e + 1] = slotBegin[e] + m * (m + 1) / 2;
  }
  positions.assign(slotBegin[E], -1);
  const Incidence incidence(pattern.n, unknowns, begin);
  // Column c's rows → their positions, in a dense table filled and cleared once per column: each
  // entry (u_i ≤ u_j = c) of an element holding c is then found without a search.
  std::vector<int> where(pattern.n, -1);
  for (int c = 0; c < pattern.n; ++c) {
    for (int q = pattern.colPtr[c]; q < pattern.colPtr[c + 1]; ++q) where[pattern.rowIdx[q]] = q;
    for (int q = incidence.start[c]; q < incidence.start[c + 1]; ++q) {
      const int k = incidence.inc[q], e = incidence.elementOf[k];
      const int m = begin[e + 1] - begin[e], j = k - begin[e];
      const int* u = unknowns.data() + begin[e];
      for (int i = 0; i < m; ++i) {
        const int a = u[i];
        if (a < 0 || a > c) continue;  // (a > c: in column a)
        if (where[a] < 0) throw std::logic_error("element entry missing from the pattern");
        positions[slotBegin[e] + upperIndex(std::min(i, j), std::max(i, j), m)] = where[a];
      }
    }
    for (int q = pattern.colPtr[c]; q < pattern.colPtr[c + 1]; ++q) where[pattern.rowIdx[q]] = -1;
  }
}

SlotTable::SlotTable(const SparsePattern& pattern, const DofMap& dofs, int arity,
                     std::span<const int> elementVertices)
    : arity_(arity) {
  const size_t count = elementVertices.size() / arity;
  const int m = 3 * arity;
  // Each element's unknowns, their positions by elementPositions (no search), then each
  // element's stored entries sorted by position.
  std::vector<int> unknowns(count * m), begin(count + 1), slotBegin, upper;
  for (size_t e = 0; e < count; ++e) {
    begin[e] = static_cast<int>(e * m);
    for (int i = 0; i < m; ++i) unknowns[e * m + i] = dofs.index(3 * elementVertices[e * arity + i / 3] + i % 3);
  }
  begin[count] = static_cast<int>(count * m);
  elementPositions(pattern, unknowns, begin, slotBegin, upper);
  std::vector<std::pair<int, int>> entries;
  for (size_t e = 0; e < count; ++e) {
    const int* u = unknowns.data() + e * m;
    const int* up = upper.data() + slotBegin[e];
    entries.clear();
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j) {
        if (u[i] < 0 || u[j] < 0 || u[i] > u[j]) continue;  // fixed, or the lower-triangle twin
        entries.emplace_back(up[upperIndex(std::min(i, j), std::max(i, j), m)], i + m * j);
      }
    entries_.add(entries);
  }
}

void ElementEntries::add(std::vector<std::pair<int, int>>& entries) {
  std::sort(entries.begin(), entries.end());
  for (const auto& [slot, local] : entries) {
    if (local < 0 || local > 255) throw std::logic_error("ElementEntries: local index past 255");
    slots_.push_back(slot);
    local_.push_back(static_cast<std::uint8_t>(local));
  }
  begin_.push_back(static_cast<int>(slots_.size()));
}

void ElementEntries::clear() {
  slots_.clear();
  local_.clear();
  begin_.assign(1, 0);
}

}  // namespace tp
