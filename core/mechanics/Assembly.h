#pragma once
// Free degrees of freedom and the fixed sparsity pattern of the tangent matrix, with per-element
// slot tables so that assembly scatters straight into CHOLMOD's value array (no triplets, no sort
// per iteration). Assembly of any element term is written once, in Model.cpp.

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace tp {

/// Maps the 3V position components to the free unknowns (clamped components are removed).
class DofMap {
 public:
  DofMap() = default;
  /// fixedDof: 3V flags (component 3v+k of vertex v), 1 = prescribed.
  explicit DofMap(const std::vector<std::uint8_t>& fixedDof);
  int fullCount() const { return static_cast<int>(index_.size()); }
  int freeCount() const { return static_cast<int>(free_.size()); }
  int index(int dof) const { return index_[dof]; }  // free index or −1
  const std::vector<int>& freeDofs() const { return free_; }

 private:
  std::vector<int> index_;
  std::vector<int> free_;
};

/// Upper triangle (row ≤ column) of a symmetric matrix over the free unknowns, compressed by
/// column with sorted row indices: the layout CHOLMOD takes with stype = +1.
struct SparsePattern {
  int n = 0;
  std::vector<int> colPtr;  // n + 1
  std::vector<int> rowIdx;  // nnz
  int nnz() const { return static_cast<int>(rowIdx.size()); }
  /// Position of (row, col), row ≤ col, in the value array, or −1 if not in the pattern.
  int find(int row, int col) const;
};

/// y = A v for the symmetric matrix A given by its upper triangle over `pattern`.
void symmetricMultiply(const SparsePattern& pattern, const std::vector<double>& values,
                       const double* v, double* y);

/// Builds the pattern from elements given as vertex lists (vertex-level adjacency, expanded to
/// 3×3 blocks). `elements` are flattened lists of `arity` vertices each.
SparsePattern buildPattern(const DofMap& dofs, int vertexCount,
                           const std::vector<std::pair<int, std::span<const int>>>& elementSets);

/// The pattern over n unknowns (free components first, then any further unknowns of a term)
/// of elements given by the lists of their unknowns (−1: a prescribed component, skipped).
SparsePattern buildPatternFromUnknowns(int n, const std::vector<std::span<const int>>& elements);

/// The value-array positions of every element's upper-triangle entries, elements given as lists
/// of unknowns (the list of element e is unknowns[begin[e], begin[e+1]), −1: none): for element
/// e of m unknowns, positions[slotBegin[e] + i·m − i(i−1)/2 + (j − i)] is the position of
/// (min(u_i, u_j), max(u_i, u_j)) for i ≤ j, or −1 when u_i or u_j is −1. Throws
/// std::logic_error if an entry is not in the pattern.
void elementPositions(const SparsePattern& pattern, std::span<const int> unknowns,
                      std::span<const int> begin, std::vector<int>& slotBegin,
                      std::vector<int>& positions);

/// Elements' stored entries as (value-array position, local index), each element's in the
/// order of their positions, so that an element's writes walk the values forward, a column's
/// entries one after another, rather than jumping between its unknowns' columns entry by entry.
class ElementEntries {
 public:
  struct Entries {
    const int* slot;
    const std::uint8_t* local;
    int count;
  };
  /// Appends the next element: its (position, local index < 256) pairs, in any order.
  void add(std::vector<std::pair<int, int>>& entries);
  Entries element(int e) const {
    return {slots_.data() + begin_[e], local_.data() + begin_[e], begin_[e + 1] - begin_[e]};
  }
  void clear();

 private:
  std::vector<int> slots_, begin_{0};
  std::vector<std::uint8_t> local_;
};

/// For every element of one kind (arity N vertices), the entries of its 3N×3N Hessian that go
/// into the value array — every stored entry once (not a fixed component, nor the lower-triangle
/// twin of a stored entry) — with local index i + 3N·j (column-major), by position.
class SlotTable {
 public:
  using Entries = ElementEntries::Entries;
  SlotTable() = default;
  SlotTable(const SparsePattern& pattern, const DofMap& dofs, int arity,
            std::span<const int> elementVertices);
  Entries element(int e) const { return entries_.element(e); }
  int arity() const { return arity_; }

 private:
  int arity_ = 0;
  ElementEntries entries_;
};

}  // namespace tp
