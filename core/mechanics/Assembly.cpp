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

SparsePattern buildPatternFromUnknowns(int n, const std::vector<std::span<const int>>& elements) {
  std::vector<std::vector<int>> upper(n);  // per column, the rows ≤ it
  for (int c = 0; c < n; ++c) upper[c].push_back(c);
  for (const auto& u : elements)
    for (int a : u) {
      if (a < 0) continue;
      for (int b : u)
        if (b >= 0 && a < b) upper[b].push_back(a);
    }
  SparsePattern p;
  p.n = n;
  p.colPtr.assign(n + 1, 0);
  for (int c = 0; c < n; ++c) {
    auto& rows = upper[c];
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    p.rowIdx.insert(p.rowIdx.end(), rows.begin(), rows.end());
    p.colPtr[c + 1] = static_cast<int>(p.rowIdx.size());
    std::vector<int>().swap(rows);
  }
  return p;
}

SlotTable::SlotTable(const SparsePattern& pattern, const DofMap& dofs, int arity,
                     std::span<const int> elementVertices)
    : arity_(arity), stride_(9 * arity * arity) {
  const size_t count = elementVertices.size() / arity;
  slots_.assign(count * stride_, -1);
  const int m = 3 * arity;
  for (size_t e = 0; e < count; ++e) {
    const int* v = elementVertices.data() + e * arity;
    int* s = slots_.data() + e * stride_;
    for (int i = 0; i < m; ++i) {
      const int gi = dofs.index(3 * v[i / 3] + i % 3);
      if (gi < 0) continue;
      for (int j = 0; j < m; ++j) {
        const int gj = dofs.index(3 * v[j / 3] + j % 3);
        if (gj < 0 || gi > gj) continue;
        const int pos = pattern.find(gi, gj);
        if (pos < 0) throw std::logic_error("SlotTable: element entry missing from the pattern");
        s[i * m + j] = pos;
      }
    }
  }
}

}  // namespace tp
