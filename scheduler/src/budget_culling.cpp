// The error budget: approximate culling with a bound on the pixels each frame loses.
// A sample threshold (OpenSceneGraph's, Unreal's) culls what looks small and says nothing
// of the error; none of the papers this project follows bounds it either. Here the
// batched raster test counts each candidate volume's samples that pass the early depth;
// a volume covers at least the pixels its part shows, and the final depth is only nearer,
// so the samples of the parts culled bound the pixels the frame loses. Those samples are
// spent like a knapsack: greedily, on the parts that save the most drawing per sample.
#include <algorithm>

#include "cull_frame.hpp"

namespace dyncull {

std::uint64_t QueryScheduler::errorBudgetPixels(const Frame& f) const {
    return dyncull::errorBudgetPixels(params_.approx.errorBudgetPercent, f.view.width, f.view.height);
}

void QueryScheduler::spendErrorBudget(Frame& f) {
    const std::uint64_t budget = errorBudgetPixels(f);
    std::uint64_t spent = f.stats.claimedErrorPixels;  // what other settings claimed already
    if (spent >= budget) return;
    budgetOrder_.clear();
    for (std::uint32_t i = 0; i < candidates_.size(); ++i) {
        const std::uint32_t samples = rasterSamples_[i];
        // Occluded ones cost nothing and are culled anyway; unknown counts cannot be bounded.
        if (rasterAnswers_[i] == QueryResult::Occluded || samples == kUnknownSamples || samples > budget - spent) continue;
        budgetOrder_.push_back({double(subtreeTriangles(f, candidates_[i])) / double(std::max(samples, 1u)), i});
    }
    // Most drawing saved per sample first; ties by candidate order (front to back), so
    // the choice is deterministic.
    std::sort(budgetOrder_.begin(), budgetOrder_.end(),
              [](const auto& a, const auto& b) { return a.first > b.first || (a.first == b.first && a.second < b.second); });
    for (const auto& [perSample, i] : budgetOrder_) {
        const std::uint32_t samples = rasterSamples_[i];
        if (samples > budget - spent) continue;  // a smaller one further on may still fit
        spent += samples;
        budgetCulled_[i] = kBudgetCulled;
        rasterAnswers_[i] = QueryResult::Occluded;
    }
    f.stats.claimedErrorPixels = spent;
}

}  // namespace dyncull
