// The floor of a culler with a pixel-error budget (issue 18): which visible items (clusters,
// or whole parts without clusters) an oracle that knows every item's own pixels leaves out
// to save the most triangles while the pixels it leaves out fit in the budget.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace dyncull {

struct BudgetDrops {
    std::vector<std::uint8_t> dropped;  ///< per item: 1 if left out
    std::uint64_t pixels = 0;           ///< pixels of the items left out (<= the budget)
    std::uint64_t triangles = 0;        ///< triangles of the items left out
    /// No set of items within the budget leaves out more triangles than this (the
    /// fractional knapsack's optimum, which bounds the 0/1 one): `triangles` is at most
    /// one item's triangles below it.
    double triangleBound = 0.0;
};

/// Items i = 0..n-1 with `triangles[i]` and `pixels[i]` (> 0; both spans of size n), taken
/// greedily by triangles per pixel, largest first, each left out if its pixels still fit in
/// `budgetPixels`. O(n log n).
BudgetDrops chooseBudgetDrops(std::span<const std::uint32_t> triangles, std::span<const std::uint32_t> pixels,
                              std::uint64_t budgetPixels);

}  // namespace dyncull
