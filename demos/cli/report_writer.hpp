// Outputs of `dyncull bench` and `dyncull sweep`: per-frame CSV (frame x mode), per-mode
// summary CSV, a Markdown report with a table in the style of the two-level paper's
// Table 1 (time, parts, queries, ratios to vfc and to the oracle, error columns), and PNG
// plots drawn by gnuplot when it is installed (time, parts and queries per frame, as the
// paper's Figures 6-9, and speed against accuracy with the Pareto front).
#pragma once

#include <cstdint>
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

#include "bench_runner.hpp"
#include "dyncull/objects/error.hpp"

namespace dyncull::cli {

/// Per-mode aggregates over all frames (means are per frame).
struct ModeSummary {
    std::string name;
    bool oracle = false;
    std::size_t frames = 0;
    double msMean = 0, msMedian = 0, msMin = 0, msMax = 0;
    double traversalMs = 0, queryMs = 0, waitMs = 0, drawMs = 0;
    double parts = 0, triangles = 0, queries = 0, occluded = 0, skippedHistory = 0, skippedOccupancy = 0, batches = 0;
    double pctWrongMean = 0, pctWrongMax = 0;
    std::uint32_t framesWrong = 0;            ///< frames with at least one pixel unlike vfc
    std::uint64_t falseNegatives = 0;         ///< summed over frames
    std::uint64_t falseNegativePixels = 0;    ///< summed over frames
    double falsePositives = 0;                ///< per frame
    double fpQueried = 0, fpHistory = 0, fpOccupancy = 0, fpOther = 0;  ///< falsePositives by cause, per frame
    double drawQueries = 0, drawQueriesOccluded = 0;  ///< per frame
    double depthTests = 0, depthReadMs = 0;           ///< per frame (full: pyramid tests, depth readback + pyramid build)
    double rasterTests = 0, rasterMs = 0;             ///< per frame (full: volumes in batched raster tests, their time)
    double pyramidBuilds = 0;                         ///< per frame (full: depth pyramids built)
    /// Per frame, measured only by full-splitwaits (SchedulerTuning::splitDrawWaits): of
    /// depthReadMs and rasterMs the waits for drawing, and the pyramid tests' CPU.
    double drawWaitMs = 0, pyramidTestMs = 0;
    double clusterPyramidTests = 0, clusterMs = 0;  ///< per frame (FrameStats::clusterPyramidTests, clusterMs)
    std::uint64_t largestRegion = 0;          ///< largest wrong region of any frame, pixels
    std::uint64_t timeouts = 0;               ///< queries that never answered, summed
    double ratioVfc = 0, ratioOracle = 0;     ///< msMean / that mode's msMean (0 if absent)
    // Query volumes (the k-DOP paper's Tables 2 and 5).
    std::string volume;            ///< the mode's volume choice; empty if it does not query node volumes
    double pctPartsCulled = 0;     ///< of the parts vfc draws, % not drawn (all frames together)
    double queryTriangles = 0;     ///< per frame, of the query volumes drawn
    /// Median over frames of this mode's ms over the fastest volume mode's ms in that same
    /// frame (modes run interleaved, so the pairing cancels load drift on a shared machine);
    /// 0 unless the mode queries node volumes.
    double pairedVsBest = 0;
    /// Over frames 1 and up (frame 0 builds every mode's history), this mode's ms over vfc's
    /// in the same frame: the median, the 95th percentile (nearest rank) and the worst, and
    /// that frame's number; 0 without vfc or a second frame.
    double vfcRatioMedian = 0, vfcRatioP95 = 0, vfcRatioMax = 0;
    std::size_t vfcRatioMaxFrame = 0;
    LeafVolumeTotals leaves;       ///< world-space leaf volumes at the last frame (leaves == 0: n/a)
    bool pareto = false;  ///< on the speed-accuracy Pareto front (the oracle never is: it is not a real mode)
    std::string family;   ///< ModeSpec::family: the curve it belongs to in the speed-accuracy plot
    bool familyFront = false;  ///< on its family's own Pareto front (the family's curve)
    // The approximate settings' claims against what was measured (ClaimCheck).
    double claimedPctMean = 0, claimedPctMax = 0;  ///< claimed error, % of the frame's pixels
    double lostPctMax = 0;                          ///< pixels lost (unlike vfc where the truth's part was not drawn), worst frame, %
    std::uint32_t framesOverClaimTruth = 0;         ///< frames whose false-negative pixels exceeded the claim
    std::uint32_t framesOverClaimImage = 0;         ///< frames whose lost pixels exceeded the claim
    std::uint32_t framesUnbounded = 0;              ///< frames where a setting without a bound culled
    std::uint64_t tiedPixels = 0;                   ///< pixels unlike vfc that no lost part explains (depth ties), summed
    double popIn = 0;                               ///< per frame
};

/// One frame's claim checked against the two measures of what it lost.
struct ClaimCheck {
    bool overTruth = false;  ///< false-negative pixels (ground truth) above the claim
    bool overImage = false;  ///< lost pixels (image against vfc, ties excluded) above the claim
};
/// Frames where a setting without a bound acted are never "over": they claim nothing.
ClaimCheck checkClaim(const ModeFrame& f);

std::vector<ModeSummary> summarise(const BenchResult& result);
/// Index of the mode named `name`, or -1.
int findMode(const std::vector<ModeSummary>& summary, const std::string& name);

/// DIR/frames.csv: one row per frame and mode with every FrameStats field and the errors.
Status writeFramesCsv(const BenchResult& result, const std::filesystem::path& path);

/// Every FrameStats field as CSV columns: the one place the frames CSVs of `dyncull run`
/// and `dyncull bench` take them from (header names, then values in the same order; no
/// leading or trailing comma).
const char* frameStatsCsvHeader();
void writeFrameStatsCsv(std::ostream& out, const FrameStats& s);
/// DIR/summary.csv: one row per mode.
Status writeSummaryCsv(const std::vector<ModeSummary>& summary, const std::filesystem::path& path);

struct PlotOutcome {
    bool gnuplotFound = false;
    std::vector<std::string> pngs;  ///< file names (relative to the output directory)
    std::string message;            ///< e.g. "gnuplot not found, plots skipped"
};
/// Writes the plot data and gnuplot script into `dir` and runs gnuplot if it is on PATH.
PlotOutcome writePlots(const BenchResult& result, const std::vector<ModeSummary>& summary,
                       const std::filesystem::path& dir);

/// True when the report gets a query-volume table: some mode queries node volumes with a
/// volume other than the default (auto) (bench --volume/--volumes, or a MODE+VOLUME name).
bool reportsVolumes(const BenchResult& result);

/// DIR/report.md. `command` is the command line shown at the top; `plots` the PNGs to embed.
/// `streaming`: the streaming summary line of a streaming scene, else empty.
Status writeReport(const BenchResult& result, const std::vector<ModeSummary>& summary, const std::string& command,
                   const std::vector<std::string>& plots, const std::string& streaming, const std::filesystem::path& path);

}  // namespace dyncull::cli
