// Cluster history: TwoPhase's early set kept per cluster, as niagara keeps a visibility bit
// per meshlet for its two-phase culling (the scheme in
// ../shared/notes/batched-occlusion-tests.md: visibility stored for the next frame). A
// cluster's bit is whether any of its fragments passed the depth test when it was drawn
// (the sink marks each range of its multi-draws), or, where the sink cannot mark, whether
// its box shows in the frame's final depth, read back into the pyramid at its end. Next
// frame an early part draws only the clusters that showed, and the late pass tests the
// others against the early pyramid (cluster_culling.cpp). The bits only choose what is
// drawn early, so a wrong bit costs time, never a pixel.
#include <algorithm>
#include <cassert>
#include <system_error>
#include <thread>

#include "cluster_selection.hpp"

namespace dyncull {

void QueryScheduler::startDeferredSelection(Frame& f) {
    if (!params_.features.useClusterWorker || deferredParts_.empty()) return;
    if (!deferredSelection_) deferredSelection_ = std::make_unique<DeferredSelection>();
    DeferredSelection& d = *deferredSelection_;
    assert(!d.worker.joinable());
    const SceneObjects& objs = f.objects;
    d.jobs.resize(deferredParts_.size());
    d.out.resize(deferredParts_.size());
    d.bits.clear();
    std::vector<std::size_t> bitOffsets(deferredParts_.size(), 0);
    for (std::size_t i = 0; i < deferredParts_.size(); ++i) {
        const NodeRef ref = deferredParts_[i].ref;
        const LocalBsp& model = objs.model(objs.modelOf(ref.object));
        ClusterJob& job = d.jobs[i];
        bool tested = false;
        [[maybe_unused]] const bool planned = planClusters(f, ref, model, model.nodes[ref.node], ClusterPass::Deferred, job, tested);
        assert(planned && "a part that deferred clusters is drawn as clusters");
        job.recordIndex = deferredParts_[i].recordIndex;
        // The words holding its bits, copied: the late pass may grow the history's storage.
        const std::size_t firstWord = job.firstBit / 64, endWord = (job.firstBit + job.clusters.size() + 63) / 64;
        bitOffsets[i] = d.bits.size();
        d.bits.insert(d.bits.end(), job.shown.begin() + static_cast<std::ptrdiff_t>(firstWord),
                      job.shown.begin() + static_cast<std::ptrdiff_t>(std::min(endWord, job.shown.size())));
        job.firstBit -= static_cast<std::uint32_t>(64 * firstWord);
    }
    for (std::size_t i = 0; i < d.jobs.size(); ++i) {
        const std::size_t end = i + 1 < d.jobs.size() ? bitOffsets[i + 1] : d.bits.size();
        d.jobs[i].shown = std::span<const std::uint64_t>(d.bits).subspan(bitOffsets[i], end - bitOffsets[i]);
    }
    d.done.store(0, std::memory_order_relaxed);
    try {
        d.worker = std::thread([this, &f, &d] {
            for (std::size_t i = 0; i < d.jobs.size(); ++i) {
                selectClusters(f, d.jobs[i], d.out[i]);
                d.done.store(i + 1, std::memory_order_release);
                d.done.notify_one();
            }
        });
    } catch (const std::system_error&) {
        // No thread to be had: drawDeferredClusters tests them itself.
    }
}

void QueryScheduler::joinDeferredSelection() {
    if (deferredSelection_ && deferredSelection_->worker.joinable()) deferredSelection_->worker.join();
}

void QueryScheduler::drawDeferredClusters(Frame& f) {
    const SceneObjects& objs = f.objects;
    // Selected on the worker (if it was started, and could be), which runs ahead of these draws.
    DeferredSelection* selected = deferredSelection_ && deferredSelection_->worker.joinable() ? deferredSelection_.get() : nullptr;
    assert(!selected || selected->jobs.size() == deferredParts_.size());
    for (std::size_t i = 0; i < deferredParts_.size(); ++i) {
        const DeferredPart& d = deferredParts_[i];
        if (selected) {
            selected->waitFor(i);
            f.stats.clusterTests += static_cast<std::uint32_t>(selected->jobs[i].clusters.size());
            takeSelection(f, selected->jobs[i], selected->out[i]);
        } else {
            const LocalBsp& model = objs.model(objs.modelOf(d.ref.object));
            cullClusters(f, d.ref, model, model.nodes[d.ref.node], ClusterPass::Deferred, d.recordIndex);
        }
        if (clusterRanges_.empty()) {
            // None of its clusters drawn in either pass: it was not drawn.
            if (!d.drawn && d.trace != kInvalidIndex) (*f.trace)[d.trace].state = NodeState::ClusterCulled;
            continue;
        }
        const auto t0 = SchedulerClock::now();
        if (d.drawn) {
            f.sink.drawMorePartRanges(d.ref, clusterRanges_);
        } else {
            f.sink.drawPartRanges(d.ref, clusterRanges_);
            ++f.stats.partsDrawn;
        }
        if (f.markClusters) noteMarkedRanges(d.ref);
        f.stats.drawMs += msSince(t0);
        for (const IndexRange& r : clusterRanges_) f.stats.trianglesDrawn += r.indexCount / 3;
    }
}

namespace {
std::span<const LeafCluster> partClusters(const SceneObjects& objs, NodeRef ref) {
    const LocalBsp& model = objs.model(objs.modelOf(ref.object));
    return model.clusters.ofSubtree(ref.node, model.nodes[ref.node].subtreeSize);
}
}  // namespace

std::uint32_t QueryScheduler::recordVerdicts(const Frame& f, std::size_t first, std::span<const NodeRef> parts, bool sinkCullsBackFaces,
                                             std::vector<std::uint8_t>& shown) const {
    using Fate = LearnedCluster::Fate;
    const SceneObjects& objs = f.objects;
    const int span = params_.tuning.recordPyramidSpan;
    shown.clear();
    std::uint32_t pyramidTests = 0;
    for (std::size_t p = 0; p < parts.size(); ++p) {
        const NodeRef ref = parts[p];
        const LocalBsp& model = objs.model(objs.modelOf(ref.object));
        const std::span<const LeafCluster> clusters = partClusters(objs, ref);
        const glm::mat4& matrix = objs.matrix(ref.object);
        const glm::mat4 toClip = f.screen.clipMatrixOf(matrix);
        // A cluster facing away now is left to next frame's late pass, should it turn: the
        // cone test is cheaper than the projection.
        const bool cones = model.faces == FaceMode::CullBack && sinkCullsBackFaces;
        const ObjectSpaceEye eye(f.camera(), matrix);
        const std::uint32_t learnedAt = clusterPartLearned_[first + p];
        const LearnedCluster* learned = learnedAt == kInvalidIndex ? nullptr : learnedClusters_.data() + learnedAt;
        for (std::size_t i = 0; i < clusters.size(); ++i) {
            const LeafCluster& c = clusters[i];
            const Fate fate = learned ? learned[i].fate : Fate::Untested;
            bool hidden = fate == Fate::Hidden;
            if (fate == Fate::Projected) {
                hidden = pyramid_.occluded(learned[i].centres, learned[i].nearest, span);
                ++pyramidTests;
            } else if (fate == Fate::Untested) {
                // No guarantee needed here (a deferred cluster is tested in the late pass),
                // so the box is projected roughly: in float, without rounding margins.
                ScreenRect centres;
                float nearest = 1.0f;
                hidden = cones && eye.backFacing(c);
                if (!hidden) {
                    hidden = f.screen.roughBoxDepth(toClip, c.box, centres, nearest) && (centres.empty() || pyramid_.occluded(centres, nearest, span));
                    ++pyramidTests;
                }
            }
            shown.push_back(hidden ? 0 : 1);
        }
    }
    return pyramidTests;
}

void QueryScheduler::recordClusterVisibility(Frame& f) {
    // The final depth holds every occluder the frame drew, so it hides the most clusters;
    // what it says only chooses next frame's early draws.
    // Read already by the parts' refresh, which would otherwise have taken a round of
    // raster tests (TestCosts::testNsPerBatch): the record pays only what the read costs more.
    const bool sharedRead = f.finalPyramid;
    if (!readFinalPyramid(f)) return;  // the bits stay as they were
    const auto t1 = SchedulerClock::now();
    const SceneObjects& objs = f.objects;
    // Each part's share of the work, in ns of TestCosts: a cluster the frame's tests left
    // untested is projected, one they projected only read again, one they hid costs nothing.
    const TestCosts& costs = params_.tuning.costs;
    recordPartNs_.assign(clusterParts_.size(), 0.0);
    double totalNs = 0.0;
    for (std::size_t p = 0; p < clusterParts_.size(); ++p) {
        const std::size_t count = partClusters(objs, clusterParts_[p]).size();
        std::size_t untested = count, projected = 0;
        if (const std::uint32_t at = clusterPartLearned_[p]; at != kInvalidIndex) {
            untested = projected = 0;
            for (std::size_t i = 0; i < count; ++i) {
                const LearnedCluster::Fate fate = learnedClusters_[at + i].fate;
                untested += fate == LearnedCluster::Fate::Untested;
                projected += fate == LearnedCluster::Fate::Projected;
            }
        }
        f.stats.clustersLearned += static_cast<std::uint32_t>(count - untested);
        recordPartNs_[p] = double(untested) * costs.recordNsPerCluster + double(projected) * costs.recordNsPerLearned;
        totalNs += recordPartNs_[p];
    }
    // All drawing is done, so the rasteriser's cores are free: with the worker, the later
    // parts (about half the work) are tested on a second thread. Each half writes its own
    // verdicts; the bits are set after the join, since two parts of one object may share a
    // word of them.
    std::size_t split = clusterParts_.size();
    if (params_.features.useClusterWorker && totalNs >= double(params_.tuning.recordWorkerClusters) * costs.recordNsPerCluster) {
        double half = 0.0;
        split = 0;
        while (split < clusterParts_.size() && 2.0 * half < totalNs) half += recordPartNs_[split++];
    }
    const std::span<const NodeRef> parts(clusterParts_);
    const bool cullsBackFaces = f.sink.cullsBackFaces();
    std::thread worker;
    std::uint32_t lateTests = 0;
    if (split < clusterParts_.size()) {
        try {
            worker = std::thread([this, &f, parts, split, cullsBackFaces, &lateTests] {
                lateTests = recordVerdicts(f, split, parts.subspan(split), cullsBackFaces, recordShownLate_);
            });
        } catch (const std::system_error&) {
            split = clusterParts_.size();  // no thread to be had: all on this one
        }
    }
    f.stats.clusterPyramidTests += recordVerdicts(f, 0, parts.first(split), cullsBackFaces, recordShown_);
    if (worker.joinable()) {
        worker.join();
        f.stats.clusterPyramidTests += lateTests;
        recordShown_.insert(recordShown_.end(), recordShownLate_.begin(), recordShownLate_.end());
    }
    std::size_t next = 0;
    for (const NodeRef ref : clusterParts_) {
        const std::size_t count = partClusters(objs, ref).size();
        const std::span<std::uint64_t> bits = history_.clusterBits(ref.object, objs);
        const std::uint32_t first = objs.model(objs.modelOf(ref.object)).clusters.nodeFirst[ref.node];
        for (std::size_t i = 0; i < count; ++i) setClusterBit(bits, first + static_cast<std::uint32_t>(i), recordShown_[next + i] != 0);
        next += count;
    }
    assert(next == recordShown_.size());
    f.stats.clusterMs += msSince(t1);
    // Its price for the cost model, from counts as every other price: a read that waits
    // for nothing plus the build, and the tests, halved where the worker shares them.
    // Timed, it swung with the frame (a wait for the drawing, a thread descheduled on two
    // cores), and one slow frame turned the record off until the next probe.
    const double threads = split < clusterParts_.size() ? 2.0 : 1.0;
    const double readNs = sharedRead ? std::max(0.0, costs.pyramidNs - costs.testNsPerBatch) : costs.pyramidNs;
    clusterRecordNs_ = readNs + totalNs / threads;
    lastClusterRecordFrame_ = f.index;
}

void QueryScheduler::noteMarkedRanges(NodeRef ref) {
    assert(clusterRangeIds_.size() == clusterRanges_.size());
    for (const std::uint32_t k : clusterRangeIds_) markedClusters_.push_back({ref.object, k});
}

void QueryScheduler::readClusterMarks(Frame& f) {
    const auto t0 = SchedulerClock::now();
    clusterMarks_.assign(markedClusters_.size(), QueryResult::Visible);
    f.sink.readRangeMarks(clusterMarks_);
    const SceneObjects& objs = f.objects;
    // A recorded part's clusters not drawn this frame (facing away, outside the frustum,
    // behind the pyramid) are left to next frame's late pass, as those drawn and hidden.
    for (const NodeRef ref : clusterParts_) {
        const LocalBsp& model = objs.model(objs.modelOf(ref.object));
        const std::span<std::uint64_t> bits = history_.clusterBits(ref.object, objs);
        const std::uint32_t first = model.clusters.nodeFirst[ref.node];
        const std::uint32_t end = first + static_cast<std::uint32_t>(partClusters(objs, ref).size());
        for (std::uint32_t k = first; k < end; ++k) setClusterBit(bits, k, false);
    }
    // Marks come back part by part: the object's bits are looked up once per run.
    std::uint32_t object = kInvalidIndex;
    std::span<std::uint64_t> bits;
    for (std::size_t i = 0; i < markedClusters_.size(); ++i) {
        if (clusterMarks_[i] == QueryResult::Occluded) continue;
        const MarkedCluster& m = markedClusters_[i];
        if (m.object != object) {
            object = m.object;
            bits = history_.clusterBits(object, objs);
        }
        setClusterBit(bits, m.cluster, true);
    }
    clusterRecordNs_ = params_.tuning.costs.pyramidNs;  // a read of the marks, priced as a depth read that waits for nothing
    f.stats.clusterMs += msSince(t0);
    lastClusterRecordFrame_ = f.index;
}

}  // namespace dyncull
