// A streamed run's per-frame residency and traffic (StreamingFrameStats), gathered by
// `run` and `bench` into one summary line and a CSV of every frame.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "dyncull/demos/demo_scene.hpp"

namespace dyncull::cli {

struct StreamingSummary {
    struct Row {
        std::uint64_t frame;
        StreamingFrameStats s;
        double frameMs;
        std::size_t rssBytes;  ///< the process's resident set at the end of the frame
    };
    std::vector<Row> rows;
    std::uint64_t frames = 0;

    /// Records one frame; reads the resident set size.
    void add(std::uint64_t frame, const StreamingFrameStats& s, double frameMs);
    /// "streaming ..." with the budget, peak residency in both memories, peak RSS, MB read
    /// and loads per frame, read-ahead hit rate, stalls (mean and worst after frame 0) and
    /// late leaves.
    std::string line(const StreamOptions& options) const;
    /// frame, resident MB (memory, GL), RSS MB, MB read, loads, evictions (both), uploads,
    /// hits, misses, stall ms, late, overflow, frame ms. Every write checked.
    Status writeCsv(const std::filesystem::path& path) const;
};

}  // namespace dyncull::cli
