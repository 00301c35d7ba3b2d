// Runs several culling configurations ("modes") interleaved over the same frames of one
// scene and measures each against the truth: the scene is moved once per frame, the exact
// visible set is computed by an ID pass (untimed), then every mode renders that frame with
// its own QueryScheduler (own visibility history), in an order rotated every frame; vfc's
// image is the reference. Shared by `dyncull bench` and `dyncull sweep` (and the
// conservative test).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "dyncull/bsp/volume_totals.hpp"
#include "dyncull/demos/demo_scene.hpp"
#include "streaming_report.hpp"
#include "dyncull/engine/engine.hpp"
#include "dyncull/measure/ground_truth.hpp"
#include "dyncull/engine/image.hpp"
#include "dyncull/measure/image_compare.hpp"
#include "dyncull/objects/error.hpp"
#include "dyncull/scheduler/query_scheduler.hpp"

namespace dyncull::cli {

/// One configuration to measure: a scheduler set-up and the query backend's parameters
/// (those live in the shared GlQueryBackend, so they are set before the mode renders), or
/// the oracle, which draws exactly the visible set with no queries (the lower bound).
struct ModeSpec {
    std::string name;
    bool oracle = false;
    /// With `oracle`: draws only the clusters of the visible parts that own a pixel (the
    /// floor of a culler at cluster granularity), not the visible parts whole.
    bool oracleClusters = false;
    /// oracle-budgetP (> 0, percent of the frame's pixels): the oracle-clusters set less the
    /// visible clusters an oracle with that error budget leaves out (chooseBudgetDrops):
    /// the floor of any error-budget culler at cluster granularity.
    double oracleBudgetPercent = 0.0;
    /// oracle-boxes: draws the frame's cluster-box bound (ClusterBound: every cluster whose
    /// box passes against the final depth), front to back, untested. The floor of any
    /// conservative culler that tests cluster boxes, measured as time; implies --volume-bound.
    bool oracleBoxes = false;
    SchedulerParams scheduler;
    GlQueryParams queries;
    /// The engine's EngineOptions::submitTriangles while this mode renders (shared like
    /// `queries`, so set before each mode).
    std::uint32_t submitTriangles = EngineOptions{}.submitTriangles;
    /// The family of settings this mode belongs to, one curve in the speed-accuracy plot:
    /// the approximations it uses (approximationFamily), or for a sweep of a conservative
    /// parameter that parameter's name; empty for a conservative named mode.
    std::string family;
};

/// The approximate settings `m` uses, named for the plots and reports ("error budget",
/// "sample threshold", "small features", "latency", joined by " + " when combined);
/// empty when the mode is conservative.
std::string approximationFamily(const ModeSpec& m);

/// A named mode: vfc, simple, full (two-phase, the default), queries (hardware queries),
/// oracle; ablations of full: full-hzb, full-nohist, full-nocost; approximate full:
/// budgetP (error budget of P percent of the frame's pixels) and its variants budgetrecountP,
/// budgetearlyP; oracle-budgetP (oracle-clusters less what an oracle with that error budget
/// leaves out); settings of queries:
/// approximate presets thrN (pixel threshold N), latency1 (last frame's results), skipN
/// (history: max skip N, 2 frames per visible answer), overlap (overlapping batches),
/// smallN (small-feature culling below N pixels); frontN (conservative: the front-most N%
/// of frustum leaves drawn without queries); ablations queries-nohist, queries-nobatch,
/// queries-noocc, queries-notight, queries-nodrawq. Settings of queries combine with '+'
/// (thr16+latency1); one part may be a volume (aabb, obb, kdop14, kdop18, kdop26, auto:
/// full+kdop26, thr16+obb) for modes that test node volumes (queriesNodeVolumes). Error
/// names the mode.
Expected<ModeSpec> modeFromName(const std::string& name);
/// True for modes whose tests use the nodes' stored volumes (queries and full with
/// tightened volumes, not the oracle), i.e. the modes a volume choice changes.
bool queriesNodeVolumes(const ModeSpec& m);
/// `--volume`: every mode that queries node volumes, and whose name does not already name
/// a volume, uses `volume` (names unchanged). Error for an unknown volume name.
Status setVolume(std::vector<ModeSpec>& modes, const std::string& volume);
/// `--volumes LIST`: each mode that queries node volumes becomes one mode per listed
/// volume, named MODE+VOLUME; other modes stay once. Errors for unknown or repeated names
/// and for modes that already name a volume.
Expected<std::vector<ModeSpec>> withVolumes(std::vector<ModeSpec> modes, const std::string& list);
/// A comma-separated list of names, e.g. "vfc,simple,full,oracle,thr16".
Expected<std::vector<ModeSpec>> modesFromList(const std::string& list);
/// Names understood by modeFromName (N stands for a number), for help texts.
std::string modeNamesHelp();

/// One `sweep --param` (given once per family): "NAME=v1,v2,..." with NAME one of
/// sweepParamsHelp()'s parameters of `queries`, or error-budget (of `full`). One mode per
/// value, named "NAME=v", all of one family. Error names the bad parameter or value, or a
/// value given twice.
Expected<std::vector<ModeSpec>> sweepModes(const std::string& spec);
std::string sweepParamsHelp();

/// Why a mode drew its false positives (drawn parts with no visible pixel): the decision
/// the scheduler's trace records for each such leaf.
struct FalsePositiveCauses {
    std::uint32_t queried = 0;    ///< a query of its volume answered visible
    std::uint32_t history = 0;    ///< drawn untested: visible in recent frames
    std::uint32_t occupancy = 0;  ///< drawn untested: its rectangle touched empty screen
    std::uint32_t other = 0;      ///< drawn untested: near plane crossed, front-most leaves, or vfc
};

/// What one mode did in one frame.
struct ModeFrame {
    FrameStats stats;
    PartErrors parts;   ///< against the ground-truth visible set
    ImageDiff image;    ///< against the vfc image of the same frame
    /// The pixels unlike vfc's, split by the ground truth's part at each: `lostPixels` where
    /// that part was not drawn (what culling lost), `tiedPixels` where it was (a depth tie
    /// drawn in another order, or background: no part was lost there).
    std::uint64_t lostPixels = 0, tiedPixels = 0;
    /// Pop-in: parts visible but not drawn in the previous frame that are drawn in this one.
    std::uint32_t popIn = 0;
    FalsePositiveCauses falsePositiveCauses;  ///< parts.falsePositives by cause (scheduler modes)
};

/// Parts whose query volume passes a query against the frame's final depth (drawn, untimed,
/// before the modes from the parts that own a pixel): what a conservative query-based mode with that volume must draw at least if
/// it had perfect order and no history. Measured only with --volume-bound.
struct VolumeBound {
    std::uint32_t parts = 0;
    std::uint64_t triangles = 0;
};

/// The same bound one level down, where parts are drawn as clusters: every cluster that
/// does not face away (its normal cone, where the model culls back faces), is not outside
/// the frustum and whose box
/// passes the batched raster test against the frame's final depth, of every part in the
/// frustum whose box, PCA box and 26-DOP all pass too (a part without clusters: the part),
/// with each passing box's samples. What a
/// conservative culler testing cluster boxes draws at least; and how many of those
/// triangles an error budget spent on box samples (of clusters, or of whole parts' boxes)
/// can leave out at most. Measured only with --volume-bound.
/// The cluster bound's default error budget, % of the frame's pixels: issue 18's target.
inline constexpr double kDefaultBoundBudgetPercent = 0.1;

struct ClusterBound {
    std::uint32_t clusters = 0;          ///< boxes that pass (clusters, and parts without clusters)
    std::uint64_t triangles = 0;         ///< their triangles
    std::uint32_t hiddenClusters = 0;    ///< of them, those owning no pixel in the ground truth
    std::uint64_t hiddenTriangles = 0;
    std::uint64_t hiddenSamples = 0;     ///< those boxes' samples (known counts only)
    std::uint32_t unknownSamples = 0;    ///< passing boxes whose samples are unknown (near plane)
    std::uint64_t budgetPixels = 0;      ///< the error budget (--bound-budget of the frame's pixels)
    /// No choice of clusters and whole parts whose box samples fit in the budget leaves out
    /// more triangles (the fractional knapsack's optimum over both kinds of item).
    double budgetTriangleBound = 0.0;
};

/// Per-frame facts independent of the mode.
struct FrameTruth {
    std::uint32_t visibleParts = 0;   ///< parts with at least one visible pixel
    std::uint32_t frustumParts = 0;   ///< parts not outside the frustum
    std::uint64_t coveredPixels = 0;  ///< pixels showing any part
    double groundTruthMs = 0.0;       ///< ID pass (not counted in any mode's time)
    double updateMs = 0.0;            ///< loose-BSP relink, once per frame for all modes
    std::uint32_t artefactPixels = 0; ///< ID-pass pixels dropped as depth artefacts (VisibleSet::artefactPixels)
    std::uint64_t visibleTriangles = 0;  ///< triangles of the visible parts (what the oracle draws)
    std::uint64_t visibleClusterTriangles = 0;  ///< triangles of their clusters that own a pixel (what oracle-clusters draws)
    bool boundMeasured = false;          ///< the two bounds below were measured (--volume-bound)
    VolumeBound boundAabb, boundAuto;    ///< with transformed local boxes, and with the auto volumes
    ClusterBound boundClusters;          ///< with cluster boxes (ClusterBound)
};

struct BenchResult {
    std::string scene;
    std::string description;
    std::string renderer;  ///< GL renderer string
    int width = 0, height = 0;
    std::vector<ModeSpec> modes;  ///< modes[0] is vfc (the reference image)
    std::vector<FrameTruth> truth;                ///< per frame
    std::vector<std::vector<ModeFrame>> frames;   ///< frames[frame][mode]
    /// Per mode: world-space totals of the leaf query volumes at the last frame (the
    /// k-DOP paper's Table 5); leaves == 0 for modes that do not query node volumes.
    std::vector<LeafVolumeTotals> leafTotals;
    /// Streaming scenes: residency and traffic per frame (all modes of the frame together).
    StreamingSummary streaming;
    /// Passes over the frames (MeasureOptions::passes): each mode's frame time is its least
    /// over the passes; everything else is the first pass's.
    std::uint32_t passes = 1;
    /// Mode-frames that drew another triangle count in a later pass than in the first
    /// (decisions that depend on measured times): their least time may be another decision's.
    std::uint64_t passFramesApart = 0;
};

/// Borrows the engine (already populated with `scene`) and the scene for its lifetime.
class BenchRunner {
public:
    /// Puts a vfc mode first (adding one if `modes` has none) and validates every mode.
    static Expected<std::unique_ptr<BenchRunner>> create(Engine& engine, DemoScene& scene, std::vector<ModeSpec> modes);

    /// Moves the scene to `frame`, computes the truth and renders every mode; appends to result().
    Status runFrame(std::uint64_t frame);
    /// Also measure the volume bounds (FrameTruth::boundAabb, boundAuto, boundClusters) each
    /// frame, untimed: two queries per part in the frustum and a raster test per cluster box.
    /// The cluster bound's budget is `budgetPercent` of the frame's pixels. Turns on the
    /// ground truth's cluster ids (which clusters own pixels).
    /// Always on when a mode is oracle-boxes.
    void setMeasureVolumeBound(bool on, double budgetPercent = kDefaultBoundBudgetPercent);
    /// Shifts the rotation of the modes' order by `offset` places: each pass of a
    /// measurement shifts it by its number, so that a mode that came first in a frame in one
    /// pass does not in the next, and each mode's least time over the passes avoids that place.
    void setOrderOffset(std::size_t offset) { orderOffset_ = offset; }
    /// Fills result().leafTotals from the scene as it is now (call after the last frame).
    void measureLeafVolumes();
    /// Takes another pass over the same frames and modes (`other`, from a fresh runner):
    /// each mode-frame keeps the lesser frame time (FrameStats::frameMs). Preconditions
    /// (asserted): the same frames and modes.
    void keepFastest(const BenchResult& other);

    const BenchResult& result() const { return result_; }
    /// Image each mode rendered in the last frame (index as result().modes).
    const std::vector<Image>& lastImages() const { return images_; }
    const VisibleSet& lastTruth() const { return truth_; }

private:
    BenchRunner(Engine& engine, DemoScene& scene) : engine_(engine), scene_(scene) {}

    Engine& engine_;
    DemoScene& scene_;
    std::unique_ptr<GroundTruth> groundTruth_;
    std::vector<std::unique_ptr<QueryScheduler>> schedulers_;  // per mode; null for the oracle
    BenchResult result_;
    VisibleSet truth_;
    std::vector<Image> images_;
    std::vector<NodeRef> oracleParts_;
    std::vector<PartRange> oracleClusterRanges_;  // oracle-clusters: oracleParts_' visible clusters, adjacent ones merged
    std::vector<std::vector<PartRange>> oracleBudgetRanges_;  // per mode: oracle-budgetP's ranges (empty for other modes)
    std::vector<std::uint64_t> oracleBudgetPixels_;           // per mode: the pixels its ranges leave out this frame
    std::vector<std::uint32_t> itemTriangles_, itemPixels_;   // the budget oracle's items: visible clusters, then clusterless parts
    std::vector<std::uint32_t> itemWholeParts_;               // the clusterless parts' indices in truth_.parts, in item order

    /// oracleParts_' visible clusters (whole parts where they have none) as ranges in `out`,
    /// adjacent ones merged, less those marked dropped (per truth_.clusters, and per
    /// truth_.parts for parts without clusters; empty spans drop nothing).
    void oracleRanges(std::span<const std::uint8_t> droppedClusters, std::span<const std::uint8_t> droppedParts,
                      std::vector<PartRange>& out) const;
    std::vector<NodeTrace> trace_;
    bool measureBound_ = false;
    std::vector<std::vector<NodeRef>> missing_;  // per mode: last frame's visible parts not drawn
    std::vector<std::vector<NodeRef>> drawn_;    // per mode: this frame's leaves drawn (runFrame's scratch)
    std::size_t orderOffset_ = 0;               // setOrderOffset
    std::vector<std::uint8_t> diffMask_;         // reused per mode and frame

    /// Queries the volume of every part in the frustum against the depth buffer as it is.
    VolumeBound volumeBound(VolumeChoice volume);
    /// Tests every cluster box of every part in the frustum against the depth buffer as it
    /// is; the passing boxes' ranges, front to back, go to boundRanges_.
    ClusterBound clusterBound();
    std::vector<PartRange> boundRanges_;  // oracle-boxes: this frame's cluster-box bound
    bool modesNeedBound_ = false;         // a mode draws boundRanges_
    double boundBudgetPercent_ = kDefaultBoundBudgetPercent;
    FalsePositiveCauses falsePositiveCauses() const;
    /// Splits `out.image`'s differing pixels (diffMask_) into lost and tied by the ground
    /// truth's part at each and whether it is among `drawn` (sorted).
    void splitDifferingPixels(const std::vector<NodeRef>& drawn, ModeFrame& out) const;
    /// Pop-in of `mode` this frame, given what it drew (sorted); remembers what it missed.
    void countPopIn(std::size_t mode, const std::vector<NodeRef>& drawn, ModeFrame& out);
};

/// What `dyncull bench` and `dyncull sweep` share: scene, frames, size, output directory.
struct MeasureOptions {
    std::string scene = "bunnies";
    std::uint64_t frames = 60;      ///< frames measured
    std::uint64_t firstFrame = 0;   ///< path frame of the first measured frame
    std::uint64_t stride = 1;       ///< measured frame i is path frame firstFrame + i * stride
    glm::ivec2 size{640, 360};  ///< framebuffer, pixels
    std::string out;  ///< output directory; empty: out/measure_<scene>
    SceneOptions sceneOptions;
    bool quiet = false;  ///< no progress lines on stderr
    bool volumeBound = false;  ///< BenchRunner::setMeasureVolumeBound
    double boundBudgetPercent = kDefaultBoundBudgetPercent;  ///< the cluster bound's error budget, % of the frame's pixels
    /// Passes over the frames, each from a fresh scene, engine and schedulers: a mode's time
    /// for a frame is its least over the passes (a quieter figure per frame on a noisy machine).
    std::uint32_t passes = 1;
};

/// Creates a headless context and engine, populates the scene, runs `modes` interleaved
/// for options.frames frames, and writes frames.csv, summary.csv, report.md, the plots and
/// last_<mode>.png into the output directory, printing what was written. `command` is
/// quoted at the top of the report. Returns the summary (ModeSummary in report_writer.hpp)
/// through `summary` when given. Errors name the option or file.
struct ModeSummary;
Status runMeasurement(const MeasureOptions& options, std::vector<ModeSpec> modes, const std::string& command,
                      std::vector<ModeSummary>* summary = nullptr);

}  // namespace dyncull::cli
