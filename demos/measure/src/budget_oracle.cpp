// Greedy knapsack by triangles per pixel: the budget oracle's choice and its bound.
#include "dyncull/measure/budget_oracle.hpp"

#include <algorithm>
#include <cassert>
#include <numeric>

namespace dyncull {

BudgetDrops chooseBudgetDrops(std::span<const std::uint32_t> triangles, std::span<const std::uint32_t> pixels,
                              std::uint64_t budgetPixels) {
    assert(triangles.size() == pixels.size());
    const std::size_t n = triangles.size();
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    // a before b when t_a / p_a > t_b / p_b, compared exactly as t_a p_b > t_b p_a (32x32 bits fit 64).
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        return std::uint64_t{triangles[a]} * pixels[b] > std::uint64_t{triangles[b]} * pixels[a];
    });
    BudgetDrops d;
    d.dropped.assign(n, 0);
    std::uint64_t left = budgetPixels;
    bool boundDone = false;
    for (const std::uint32_t i : order) {
        assert(pixels[i] > 0);
        if (!boundDone) {
            // The fractional optimum takes the items whole in this order, then the fitting
            // fraction of the first that does not fit; up to that item the greedy took the same.
            if (pixels[i] <= left) {
                d.triangleBound += triangles[i];
            } else {
                d.triangleBound += double(triangles[i]) * double(left) / double(pixels[i]);
                boundDone = true;
            }
        }
        if (pixels[i] > left) continue;  // greedy goes on with smaller items
        d.dropped[i] = 1;
        left -= pixels[i];
        d.pixels += pixels[i];
        d.triangles += triangles[i];
    }
    return d;
}

}  // namespace dyncull
