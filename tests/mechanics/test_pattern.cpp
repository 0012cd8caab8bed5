// The tangent's sparsity pattern and the element → value-array position tables
// (mechanics/Assembly.h), against a set of entries built directly and SparsePattern::find.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include "mechanics/Assembly.h"

using namespace tp;

namespace {

// Random elements over n unknowns: 1-12 entries each, some −1 (prescribed), some repeated.
struct RandomElements {
  std::vector<int> flat, begin{0};
  RandomElements(int n, int count, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> size(1, 12), unknown(-1, n - 1);
    for (int e = 0; e < count; ++e) {
      const int m = size(rng);
      for (int k = 0; k < m; ++k) flat.push_back(k > 0 && k % 5 == 0 ? flat.back() : unknown(rng));
      begin.push_back(static_cast<int>(flat.size()));
    }
  }
  std::vector<std::span<const int>> spans() const {
    std::vector<std::span<const int>> s;
    for (size_t e = 0; e + 1 < begin.size(); ++e)
      s.emplace_back(flat.data() + begin[e], begin[e + 1] - begin[e]);
    return s;
  }
};

}  // namespace

TEST(Pattern, FromUnknownListsHoldsExactlyTheCoupledPairs) {
  const int n = 300;
  const RandomElements el(n, 400, 7);
  std::set<std::pair<int, int>> expected;  // (row, col), row ≤ col
  for (int c = 0; c < n; ++c) expected.emplace(c, c);
  for (const auto& u : el.spans())
    for (int a : u)
      for (int b : u)
        if (a >= 0 && b >= 0) expected.emplace(std::min(a, b), std::max(a, b));
  const SparsePattern p = buildPatternFromUnknowns(n, el.spans());
  ASSERT_EQ(p.n, n);
  ASSERT_EQ(static_cast<int>(p.colPtr.size()), n + 1);
  std::set<std::pair<int, int>> got;
  for (int c = 0; c < n; ++c) {
    for (int q = p.colPtr[c]; q < p.colPtr[c + 1]; ++q) {
      if (q > p.colPtr[c]) {
        EXPECT_LT(p.rowIdx[q - 1], p.rowIdx[q]) << "rows of column " << c;
      }
      got.emplace(p.rowIdx[q], c);
    }
  }
  EXPECT_EQ(got.size(), expected.size());
  EXPECT_TRUE(got == expected);
}

TEST(Pattern, ElementPositionsAreThoseFindGives) {
  const int n = 250;
  const RandomElements el(n, 300, 11);
  const SparsePattern p = buildPatternFromUnknowns(n, el.spans());
  std::vector<int> slotBegin, positions;
  elementPositions(p, el.flat, el.begin, slotBegin, positions);
  ASSERT_EQ(slotBegin.size(), el.begin.size());
  int checked = 0;
  for (size_t e = 0; e + 1 < el.begin.size(); ++e) {
    const int* u = el.flat.data() + el.begin[e];
    const int m = el.begin[e + 1] - el.begin[e];
    ASSERT_EQ(slotBegin[e + 1] - slotBegin[e], m * (m + 1) / 2);
    int k = slotBegin[e];
    for (int i = 0; i < m; ++i)
      for (int j = i; j < m; ++j, ++k) {
        const int want = u[i] < 0 || u[j] < 0 ? -1 : p.find(std::min(u[i], u[j]), std::max(u[i], u[j]));
        ASSERT_EQ(positions[k], want) << "element " << e << " entry (" << i << ", " << j << ")";
        checked += want >= 0;
      }
  }
  EXPECT_GT(checked, 1000);
}

TEST(Pattern, ElementPositionsRefuseAnEntryMissingFromThePattern) {
  const int n = 50;
  const RandomElements el(n, 60, 3);
  auto spans = el.spans();
  // The pattern of the elements but the one with the most entries: that one's are missing.
  const auto largest = std::max_element(spans.begin(), spans.end(),
                                        [](auto a, auto b) { return a.size() < b.size(); });
  spans.erase(largest);
  const SparsePattern p = buildPatternFromUnknowns(n, spans);
  std::vector<int> slotBegin, positions;
  EXPECT_THROW(elementPositions(p, el.flat, el.begin, slotBegin, positions), std::logic_error);
}

TEST(Pattern, SlotTableHitsEveryStoredEntryOnceThroughFind) {
  // Triangles of a strip of 40 vertices, every fifth vertex's z clamped.
  const int V = 40;
  std::vector<int> tris;
  for (int v = 0; v + 2 < V; ++v) tris.insert(tris.end(), {v, v + 1, v + 2});
  std::vector<std::uint8_t> fixed(3 * V, 0);
  for (int v = 0; v < V; v += 5) fixed[3 * v + 2] = 1;
  const DofMap dofs(fixed);
  const SparsePattern p = buildPattern(dofs, V, {{3, std::span<const int>(tris)}});
  const SlotTable slots(p, dofs, 3, tris);
  const int count = static_cast<int>(tris.size()) / 3;
  for (int e = 0; e < count; ++e) {
    // The element's entries as a 9×9 table of positions (local index i + 9j), −1 where absent;
    // each local entry at most once, the positions increasing.
    const SlotTable::Entries entries = slots.element(e);
    std::vector<int> s(81, -1);
    for (int q = 0; q < entries.count; ++q) {
      ASSERT_LT(entries.local[q], 81);
      ASSERT_EQ(s[entries.local[q]], -1) << "element " << e << ": local entry twice";
      s[entries.local[q]] = entries.slot[q];
      if (q > 0) {
        ASSERT_LT(entries.slot[q - 1], entries.slot[q]) << "element " << e;
      }
    }
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < 9; ++j) {
        const int gi = dofs.index(3 * tris[3 * e + i / 3] + i % 3);
        const int gj = dofs.index(3 * tris[3 * e + j / 3] + j % 3);
        const int want = gi < 0 || gj < 0 || gi > gj ? -1 : p.find(gi, gj);
        ASSERT_EQ(s[i + 9 * j], want) << "element " << e << " entry (" << i << ", " << j << ")";
      }
  }
}
