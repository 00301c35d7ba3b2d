// CSV, Markdown and gnuplot outputs of bench and sweep (see report_writer.hpp).
#include "report_writer.hpp"

#include "dyncull/objects/checked_write.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace dyncull::cli {
namespace fs = std::filesystem;
namespace {

std::string fmt(double v, int decimals) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

/// Single-quoted gnuplot string (backslashes are literal inside single quotes; a quote is doubled).
std::string gpQuote(const std::string& s) {
    std::string out = "'";
    for (char c : s) {
        if (c == '\'') out += "''";
        else out += c;
    }
    return out + "'";
}

std::string shellQuote(const std::string& s) {
    std::string out = "'";
    for (char c : s) {
        if (c == '\'') out += "'\\''";
        else out += c;
    }
    return out + "'";
}

/// First executable `name` on $PATH, or empty.
std::string findOnPath(const std::string& name) {
    const char* path = std::getenv("PATH");
    if (!path) return {};
    std::stringstream ss(path);
    std::string dir;
    while (std::getline(ss, dir, ':')) {
        if (dir.empty()) continue;
        const fs::path p = fs::path(dir) / name;
        std::error_code ec;
        const auto st = fs::status(p, ec);
        if (!ec && fs::is_regular_file(st) && (st.permissions() & fs::perms::others_exec) != fs::perms::none)
            return p.string();
    }
    return {};
}

}  // namespace

int findMode(const std::vector<ModeSummary>& summary, const std::string& name) {
    for (std::size_t i = 0; i < summary.size(); ++i)
        if (summary[i].name == name) return static_cast<int>(i);
    return -1;
}

ClaimCheck checkClaim(const ModeFrame& f) {
    if (f.stats.claimUnbounded) return {};
    return {f.parts.falseNegativePixels > f.stats.claimedErrorPixels, f.lostPixels > f.stats.claimedErrorPixels};
}

std::vector<ModeSummary> summarise(const BenchResult& r) {
    std::vector<ModeSummary> out(r.modes.size());
    for (std::size_t m = 0; m < r.modes.size(); ++m) {
        ModeSummary& s = out[m];
        s.name = r.modes[m].name;
        s.oracle = r.modes[m].oracle;
        s.family = r.modes[m].family;
        s.frames = r.frames.size();
        std::vector<double> ms;
        for (const auto& row : r.frames) {
            const ModeFrame& f = row[m];
            ms.push_back(f.stats.frameMs);
            s.traversalMs += f.stats.traversalMs;
            s.queryMs += f.stats.queryMs;
            s.waitMs += f.stats.waitMs;
            s.drawMs += f.stats.drawMs;
            s.parts += f.stats.partsDrawn;
            s.triangles += static_cast<double>(f.stats.trianglesDrawn);
            s.queries += f.stats.queriesIssued;
            s.occluded += f.stats.queriesOccluded;
            s.skippedHistory += f.stats.skippedByHistory;
            s.skippedOccupancy += f.stats.skippedByOccupancy;
            s.batches += f.stats.batches;
            s.pctWrongMean += f.image.percentDiffering;
            s.pctWrongMax = std::max(s.pctWrongMax, f.image.percentDiffering);
            if (f.image.differingPixels) ++s.framesWrong;
            s.falseNegatives += f.parts.falseNegatives;
            s.falseNegativePixels += f.parts.falseNegativePixels;
            s.falsePositives += f.parts.falsePositives;
            s.fpQueried += f.falsePositiveCauses.queried;
            s.fpHistory += f.falsePositiveCauses.history;
            s.fpOccupancy += f.falsePositiveCauses.occupancy;
            s.fpOther += f.falsePositiveCauses.other;
            s.drawQueries += f.stats.drawQueries;
            s.drawQueriesOccluded += f.stats.drawQueriesOccluded;
            s.depthTests += f.stats.depthTests;
            s.depthReadMs += f.stats.depthReadMs;
            s.rasterTests += f.stats.rasterTests;
            s.rasterMs += f.stats.rasterMs;
            s.pyramidBuilds += f.stats.pyramidBuilds;
            s.drawWaitMs += f.stats.drawWaitMs;
            s.pyramidTestMs += f.stats.pyramidTestMs;
            s.clusterPyramidTests += f.stats.clusterPyramidTests;
            s.clusterMs += f.stats.clusterMs;
            s.largestRegion = std::max(s.largestRegion, f.image.largestRegion);
            s.timeouts += f.stats.queriesTimedOut;
            const double framePixels = std::max(1.0, double(r.width) * double(r.height));
            const double claimed = 100.0 * double(f.stats.claimedErrorPixels) / framePixels;
            s.claimedPctMean += claimed;
            s.claimedPctMax = std::max(s.claimedPctMax, claimed);
            s.lostPctMax = std::max(s.lostPctMax, 100.0 * double(f.lostPixels) / framePixels);
            const ClaimCheck k = checkClaim(f);
            s.framesOverClaimTruth += k.overTruth;
            s.framesOverClaimImage += k.overImage;
            s.framesUnbounded += f.stats.claimUnbounded;
            s.tiedPixels += f.tiedPixels;
            s.popIn += f.popIn;
        }
        if (ms.empty()) continue;
        const double n = static_cast<double>(ms.size());
        for (double v : ms) s.msMean += v;
        s.msMean /= n;
        for (double* v : {&s.traversalMs, &s.queryMs, &s.waitMs, &s.drawMs, &s.parts, &s.triangles, &s.queries, &s.occluded,
                          &s.skippedHistory, &s.skippedOccupancy, &s.batches, &s.pctWrongMean, &s.falsePositives, &s.fpQueried,
                          &s.fpHistory, &s.fpOccupancy, &s.fpOther, &s.drawQueries, &s.drawQueriesOccluded, &s.depthTests,
                          &s.depthReadMs, &s.rasterTests, &s.rasterMs, &s.pyramidBuilds, &s.drawWaitMs, &s.pyramidTestMs, &s.clusterPyramidTests, &s.clusterMs,
                          &s.claimedPctMean, &s.popIn})
            *v /= n;
        std::sort(ms.begin(), ms.end());
        s.msMin = ms.front();
        s.msMax = ms.back();
        s.msMedian = ms.size() % 2 ? ms[ms.size() / 2] : 0.5 * (ms[ms.size() / 2 - 1] + ms[ms.size() / 2]);
    }
    const int vfc = findMode(out, "vfc");
    double vfcParts = 0;
    if (vfc >= 0)
        for (const auto& row : r.frames) vfcParts += row[static_cast<std::size_t>(vfc)].stats.partsDrawn;
    for (std::size_t m = 0; m < r.modes.size(); ++m) {
        ModeSummary& s = out[m];
        double parts = 0, tris = 0;
        for (const auto& row : r.frames) {
            parts += row[m].stats.partsDrawn;
            tris += static_cast<double>(row[m].stats.queryTriangles);
        }
        if (vfcParts > 0) s.pctPartsCulled = 100.0 * (vfcParts - parts) / vfcParts;
        if (!r.frames.empty()) s.queryTriangles = tris / static_cast<double>(r.frames.size());
        if (queriesNodeVolumes(r.modes[m])) s.volume = toString(r.modes[m].scheduler.tuning.volume);
        if (m < r.leafTotals.size()) s.leaves = r.leafTotals[m];
    }
    std::vector<double> ratios;
    for (std::size_t m = 0; m < r.modes.size(); ++m) {
        if (!queriesNodeVolumes(r.modes[m]) || r.frames.empty()) continue;
        ratios.clear();
        for (const auto& row : r.frames) {
            double best = 0;
            for (std::size_t k = 0; k < r.modes.size(); ++k)
                if (queriesNodeVolumes(r.modes[k]) && (best == 0 || row[k].stats.frameMs < best)) best = row[k].stats.frameMs;
            if (best > 0) ratios.push_back(row[m].stats.frameMs / best);
        }
        if (ratios.empty()) continue;
        std::sort(ratios.begin(), ratios.end());
        const std::size_t h = ratios.size() / 2;
        out[m].pairedVsBest = ratios.size() % 2 ? ratios[h] : 0.5 * (ratios[h - 1] + ratios[h]);
    }
    if (vfc >= 0 && r.frames.size() > 1) {
        for (std::size_t m = 0; m < r.modes.size(); ++m) {
            std::vector<std::pair<double, std::size_t>> byFrame;
            for (std::size_t k = 1; k < r.frames.size(); ++k) {
                const double base = r.frames[k][static_cast<std::size_t>(vfc)].stats.frameMs;
                if (base > 0) byFrame.push_back({r.frames[k][m].stats.frameMs / base, k});
            }
            if (byFrame.empty()) continue;
            std::sort(byFrame.begin(), byFrame.end());
            const std::size_t n = byFrame.size(), h = n / 2;
            ModeSummary& s = out[m];
            s.vfcRatioMedian = n % 2 ? byFrame[h].first : 0.5 * (byFrame[h - 1].first + byFrame[h].first);
            s.vfcRatioP95 = byFrame[(95 * n + 99) / 100 - 1].first;  // nearest rank: ceil(0.95 n)
            s.vfcRatioMax = byFrame.back().first;
            s.vfcRatioMaxFrame = byFrame.back().second;
        }
    }
    int oracle = -1;
    for (std::size_t i = 0; i < out.size(); ++i)
        if (out[i].oracle && (oracle < 0 || out[i].name == "oracle")) oracle = static_cast<int>(i);  // "vs oracle": the parts' oracle
    for (ModeSummary& s : out) {
        if (vfc >= 0 && out[vfc].msMean > 0) s.ratioVfc = s.msMean / out[vfc].msMean;
        if (oracle >= 0 && out[oracle].msMean > 0) s.ratioOracle = s.msMean / out[oracle].msMean;
    }
    // Pareto front over (mean ms, mean % pixels wrong) among real modes: a mode is on it
    // unless another is no slower and no less accurate, and strictly better in one.
    // The same within each family of settings: that family's curve.
    auto dominates = [](const ModeSummary& b, const ModeSummary& a) {
        return &b != &a && b.msMean <= a.msMean && b.pctWrongMean <= a.pctWrongMean &&
               (b.msMean < a.msMean || b.pctWrongMean < a.pctWrongMean);
    };
    for (ModeSummary& a : out) {
        if (a.oracle) continue;
        a.pareto = std::none_of(out.begin(), out.end(), [&](const ModeSummary& b) { return !b.oracle && dominates(b, a); });
        a.familyFront = !a.family.empty() && std::none_of(out.begin(), out.end(), [&](const ModeSummary& b) {
            return !b.oracle && b.family == a.family && dominates(b, a);
        });
    }
    return out;
}

const char* frameStatsCsvHeader() {
    return "ms_frame,ms_traversal,ms_query,ms_wait,ms_draw,ms_update,queries,queries_occluded,queries_timed_out,"
           "skipped_history,skipped_occupancy,skipped_cost,visible_near,visible_front,frustum_culled,small_feature_culled,"
           "nodes_visited,batches,parts,triangles,query_triangles,draw_queries,draw_queries_occluded,draw_queries_late,"
           "depth_tests,ms_depth_read,raster_tests,raster_batches,ms_raster,triangle_tests,ms_triangle_test,draw_marks_hidden,"
           "cluster_tests,clusters_culled,cluster_triangles_culled,clusters_deferred,deferred_clusters_drawn,ms_clusters,budget_culled,claimed_error_pixels,claim_unbounded,"
           "early_triangles,tested_triangles,pyramid_builds,ms_draw_wait,ms_pyramid_tests,draw_submits,clusters_learned,texel_occluded,"
           "cluster_pyramid_tests";
}

void writeFrameStatsCsv(std::ostream& f, const FrameStats& s) {
    f << s.frameMs << ',' << s.traversalMs << ',' << s.queryMs << ',' << s.waitMs << ',' << s.drawMs << ',' << s.updateMs << ','
      << s.queriesIssued << ',' << s.queriesOccluded << ',' << s.queriesTimedOut << ',' << s.skippedByHistory << ','
      << s.skippedByOccupancy << ',' << s.skippedByCost << ',' << s.visibleNearOrInside << ',' << s.visibleFront << ','
      << s.frustumCulled << ',' << s.smallFeatureCulled << ',' << s.nodesVisited << ',' << s.batches << ','
      << s.partsDrawn << ',' << s.trianglesDrawn << ',' << s.queryTriangles << ',' << s.drawQueries << ','
      << s.drawQueriesOccluded << ',' << s.drawQueriesLate << ',' << s.depthTests << ',' << s.depthReadMs << ','
      << s.rasterTests << ',' << s.rasterBatches << ',' << s.rasterMs << ',' << s.triangleTests << ','
      << s.triangleTestMs << ',' << s.drawMarksHidden << ',' << s.clusterTests << ',' << s.clustersCulled << ','
      << s.clusterTrianglesCulled << ',' << s.clustersDeferred << ',' << s.deferredClustersDrawn << ',' << s.clusterMs << ',' << s.budgetCulled << ',' << s.claimedErrorPixels << ','
      << (s.claimUnbounded ? 1 : 0) << ',' << s.earlyTriangles << ',' << s.testedTriangles << ',' << s.pyramidBuilds << ',' << s.drawWaitMs << ','
      << s.pyramidTestMs << ',' << s.drawSubmits << ',' << s.clustersLearned << ',' << s.texelOccluded << ','
      << s.clusterPyramidTests;
}

Status writeFramesCsv(const BenchResult& r, const fs::path& path) {
    std::ofstream f;
    if (Status s = openChecked(f, path); !s) return s;
    f << "frame,mode," << frameStatsCsvHeader()
      << ",visible_parts,frustum_parts,false_negatives,false_negative_pixels,false_positives,"
         "pixels_wrong,pixels_wrong_pct,largest_wrong_region,frame_update_ms,ground_truth_ms,ground_truth_artefact_pixels,"
         "false_positives_queried,false_positives_history,false_positives_occupancy,false_positives_other,"
         "visible_triangles,visible_cluster_triangles,pixels_lost,pixels_tied,claimed_error_pct,over_claim_truth,over_claim_image,pop_in,"
         "bound_aabb_parts,bound_aabb_triangles,bound_auto_parts,bound_auto_triangles,"
         "bound_clusters,bound_cluster_triangles,bound_hidden_clusters,bound_hidden_cluster_triangles,bound_hidden_cluster_samples,"
         "bound_unknown_samples,bound_budget_pixels,bound_budget_triangles_max\n";
    for (std::size_t i = 0; i < r.frames.size(); ++i) {
        const FrameTruth& t = r.truth[i];
        for (std::size_t m = 0; m < r.modes.size(); ++m) {
            const PartErrors& p = r.frames[i][m].parts;
            const ImageDiff& d = r.frames[i][m].image;
            f << i << ',' << r.modes[m].name << ',';
            writeFrameStatsCsv(f, r.frames[i][m].stats);
            f << ',' << t.visibleParts << ',' << t.frustumParts << ',' << p.falseNegatives << ',' << p.falseNegativePixels
              << ',' << p.falsePositives << ',' << d.differingPixels << ',' << d.percentDiffering << ','
              << d.largestRegion << ',' << t.updateMs << ',' << t.groundTruthMs << ',' << t.artefactPixels << ',';
            const FalsePositiveCauses& c = r.frames[i][m].falsePositiveCauses;
            f << c.queried << ',' << c.history << ',' << c.occupancy << ',' << c.other << ',' << t.visibleTriangles << ',' << t.visibleClusterTriangles;
            const ModeFrame& mf = r.frames[i][m];
            const ClaimCheck k = checkClaim(mf);
            f << ',' << mf.lostPixels << ',' << mf.tiedPixels << ',' << 100.0 * double(mf.stats.claimedErrorPixels) / double(r.width * r.height)
              << ',' << (k.overTruth ? 1 : 0) << ',' << (k.overImage ? 1 : 0) << ',' << mf.popIn;
            const ClusterBound& cb = t.boundClusters;
            if (t.boundMeasured)
                f << ',' << t.boundAabb.parts << ',' << t.boundAabb.triangles << ',' << t.boundAuto.parts << ','
                  << t.boundAuto.triangles << ',' << cb.clusters << ',' << cb.triangles << ',' << cb.hiddenClusters << ','
                  << cb.hiddenTriangles << ',' << cb.hiddenSamples << ',' << cb.unknownSamples << ',' << cb.budgetPixels << ','
                  << cb.budgetTriangleBound << '\n';
            else
                f << ",,,,,,,,,,,\n";  // not measured
        }
    }
    return closeChecked(f, path);
}

Status writeSummaryCsv(const std::vector<ModeSummary>& summary, const fs::path& path) {
    std::ofstream f;
    if (Status s = openChecked(f, path); !s) return s;
    f << "mode,frames,ms_mean,ms_median,ms_min,ms_max,ms_traversal,ms_query,ms_wait,ms_draw,ratio_vfc,ratio_oracle,parts,"
         "triangles,queries,queries_occluded,skipped_history,skipped_occupancy,batches,pixels_wrong_pct_mean,"
         "pixels_wrong_pct_max,frames_wrong,false_negatives,false_negative_pixels,false_positives_per_frame,"
         "largest_wrong_region,timeouts,pareto,volume,pct_parts_culled,query_triangles,leaf_volume,"
         "leaf_surface_area,leaf_triangles_mean,leaf_triangles_max,paired_vs_best,false_positives_queried,"
         "false_positives_history,false_positives_occupancy,false_positives_other,draw_queries,draw_queries_occluded,"
         "depth_tests,ms_depth_read,raster_tests,ms_raster,claimed_error_pct_mean,claimed_error_pct_max,"
         "pixels_lost_pct_max,frames_over_claim_truth,frames_over_claim_image,frames_unbounded,pixels_tied,pop_in_per_frame,pyramid_builds,"
         "frame_ratio_vfc_median,frame_ratio_vfc_p95,frame_ratio_vfc_max\n";
    for (const ModeSummary& s : summary)
        f << s.name << ',' << s.frames << ',' << s.msMean << ',' << s.msMedian << ',' << s.msMin << ',' << s.msMax
          << ',' << s.traversalMs << ',' << s.queryMs << ',' << s.waitMs << ',' << s.drawMs << ',' << s.ratioVfc << ',' << s.ratioOracle
          << ',' << s.parts << ',' << s.triangles << ',' << s.queries << ',' << s.occluded << ',' << s.skippedHistory
          << ',' << s.skippedOccupancy << ',' << s.batches << ',' << s.pctWrongMean << ',' << s.pctWrongMax << ','
          << s.framesWrong << ',' << s.falseNegatives << ',' << s.falseNegativePixels << ',' << s.falsePositives
          << ',' << s.largestRegion << ',' << s.timeouts << ',' << (s.pareto ? 1 : 0) << ',' << s.volume << ','
          << s.pctPartsCulled << ',' << s.queryTriangles << ',' << s.leaves.volume << ',' << s.leaves.surfaceArea << ','
          << (s.leaves.leaves ? static_cast<double>(s.leaves.triangles) / static_cast<double>(s.leaves.leaves) : 0.0)
          << ',' << s.leaves.maxTriangles << ',' << s.pairedVsBest << ',' << s.fpQueried << ',' << s.fpHistory << ','
          << s.fpOccupancy << ',' << s.fpOther << ',' << s.drawQueries << ',' << s.drawQueriesOccluded << ','
          << s.depthTests << ',' << s.depthReadMs << ',' << s.rasterTests << ',' << s.rasterMs << ',' << s.claimedPctMean
          << ',' << s.claimedPctMax << ',' << s.lostPctMax << ',' << s.framesOverClaimTruth << ',' << s.framesOverClaimImage
          << ',' << s.framesUnbounded << ',' << s.tiedPixels << ',' << s.popIn << ',' << s.pyramidBuilds << ','
          << s.vfcRatioMedian << ',' << s.vfcRatioP95 << ',' << s.vfcRatioMax << '\n';
    return closeChecked(f, path);
}

PlotOutcome writePlots(const BenchResult& r, const std::vector<ModeSummary>& summary, const fs::path& dir) {
    PlotOutcome out;
    const std::string gnuplot = findOnPath("gnuplot");
    if (gnuplot.empty()) {
        out.message = "gnuplot not found, plots skipped";
        return out;
    }
    out.gnuplotFound = true;
    // Wide per-frame table: frame, then ms, parts, queries of each mode in turn.
    // A plot file that cannot be written skips the plots with the reason; the report goes on.
    auto skipped = [&out](const Status& s) {
        out.message = s.message() + "; plots skipped";
        return out;
    };
    {
        std::ofstream f;
        if (Status s = openChecked(f, dir / "plot_frames.dat"); !s) return skipped(s);
        f << "# frame";
        for (const ModeSpec& m : r.modes) f << ' ' << m.name << "_ms " << m.name << "_parts " << m.name << "_queries";
        f << '\n';
        for (std::size_t i = 0; i < r.frames.size(); ++i) {
            f << i;
            for (const ModeFrame& mf : r.frames[i])
                f << ' ' << mf.stats.frameMs << ' ' << mf.stats.partsDrawn << ' ' << mf.stats.queriesIssued;
            f << '\n';
        }
        if (Status s = closeChecked(f, dir / "plot_frames.dat"); !s) return skipped(s);
    }
    {
        std::ofstream f, front;
        if (Status s = openChecked(f, dir / "plot_pareto.dat"); !s) return skipped(s);
        if (Status s = openChecked(front, dir / "plot_front.dat"); !s) return skipped(s);
        f << "# mode ms_mean pixels_wrong_pct_mean pareto\n";
        for (const ModeSummary& s : summary)
            f << '"' << s.name << "\" " << s.msMean << ' ' << s.pctWrongMean << ' ' << (s.pareto ? 1 : 0) << '\n';
        std::vector<const ModeSummary*> pts;
        for (const ModeSummary& s : summary)
            if (s.pareto) pts.push_back(&s);
        std::sort(pts.begin(), pts.end(), [](auto* a, auto* b) { return a->msMean < b->msMean; });
        front << "# ms_mean pixels_wrong_pct_mean (Pareto front, by time)\n";
        for (auto* s : pts) front << s->msMean << ' ' << s->pctWrongMean << '\n';
        if (Status s = closeChecked(f, dir / "plot_pareto.dat"); !s) return skipped(s);
        if (Status s = closeChecked(front, dir / "plot_front.dat"); !s) return skipped(s);
    }
    // One data block per family of approximate settings (gnuplot's `index`): its front, by time.
    std::vector<std::string> families;
    for (const ModeSummary& s : summary)
        if (!s.family.empty() && std::find(families.begin(), families.end(), s.family) == families.end())
            families.push_back(s.family);
    {
        std::ofstream f;
        if (Status s = openChecked(f, dir / "plot_families.dat"); !s) return skipped(s);
        for (const std::string& family : families) {
            f << "# family: " << family << " (ms_mean pixels_wrong_pct_mean, its Pareto front by time)\n";
            std::vector<const ModeSummary*> pts;
            for (const ModeSummary& s : summary)
                if (s.family == family && s.familyFront) pts.push_back(&s);
            std::sort(pts.begin(), pts.end(), [](auto* a, auto* b) { return a->msMean < b->msMean; });
            for (auto* s : pts) f << s->msMean << ' ' << s->pctWrongMean << '\n';
            f << "\n\n";
        }
        if (Status s = closeChecked(f, dir / "plot_families.dat"); !s) return skipped(s);
    }
    std::string names;
    for (const ModeSpec& m : r.modes) names += (names.empty() ? "" : " ") + m.name;
    const std::string title = r.scene + ", " + std::to_string(r.width) + "x" + std::to_string(r.height) + ", " +
                              std::to_string(r.frames.size()) + " frames";
    std::ofstream gp;
    if (Status s = openChecked(gp, dir / "plots.gp"); !s) return skipped(s);
    gp << "# gnuplot script written by dyncull bench/sweep; run it in this directory.\n"
       << "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
       << "  set terminal pngcairo size 1100,620 noenhanced font 'sans,10'\n"
       << "} else {\n"
       << "  set terminal png size 1100,620 noenhanced\n"
       << "}\n"
       << "names = " << gpQuote(names) << "\n"
       << "n = words(names)\n"
       << "data = " << gpQuote((dir / "plot_frames.dat").string()) << "\n"
       << "# 8 colours, then the same colours dashed, so every mode stays distinguishable\n"
       << "set grid\nset key outside right top\nset xlabel 'frame'\n"
       << "set output " << gpQuote((dir / "time_per_frame.png").string()) << "\n"
       << "set title " << gpQuote("Time per frame (" + title + ")") << "\nset ylabel 'ms'\n"
       << "plot for [i=1:n] data using 1:(column(2 + 3*(i-1))) with lines lw 1.5 lc i dt 1 + (i - 1) / 8 title word(names, i)\n"
       << "set output " << gpQuote((dir / "parts_per_frame.png").string()) << "\n"
       << "set title " << gpQuote("Object parts drawn per frame (" + title + ")") << "\nset ylabel 'parts'\n"
       << "plot for [i=1:n] data using 1:(column(3 + 3*(i-1))) with lines lw 1.5 lc i dt 1 + (i - 1) / 8 title word(names, i)\n"
       << "set output " << gpQuote((dir / "queries_per_frame.png").string()) << "\n"
       << "set title " << gpQuote("Occlusion queries per frame (" + title + ")") << "\nset ylabel 'queries'\n"
       << "plot for [i=1:n] data using 1:(column(4 + 3*(i-1))) with lines lw 1.5 lc i dt 1 + (i - 1) / 8 title word(names, i)\n"
       << "set output " << gpQuote((dir / "speed_vs_accuracy.png").string()) << "\n"
       << "set title " << gpQuote("Speed vs accuracy (" + title + "); oracle = lower bound, not on the front")
       << "\nset xlabel 'mean ms per frame'\nset ylabel 'mean % pixels unlike vfc (log; exact 0 drawn at 1e-5)'\n"
       // Log scale spreads the tiny tie-order differences of exact modes from the real
       // errors of approximate ones; a log axis cannot show 0, so 0 sits on the floor.
       << "set logscale y\nset format y '%g'\natleast(v) = v > 1e-5 ? v : 1e-5\n"
       << "set offsets graph 0.08, graph 0.15, 0, 0\n"
       << "plot " << gpQuote((dir / "plot_front.dat").string())
       << " using 1:(atleast($2)) with lines lw 6 lc rgb '#e0e0e0' title 'Pareto front of all modes', \\\n";
    for (std::size_t i = 0; i < families.size(); ++i)
        gp << "     " << gpQuote((dir / "plot_families.dat").string()) << " index " << i
           << " using 1:(atleast($2)) with linespoints lw 2 pt 7 ps 1.3 lc " << i + 1 << " title "
           << gpQuote(families[i]) << ", \\\n";
    gp << "     " << gpQuote((dir / "plot_pareto.dat").string())
       << " using 2:(atleast($3)) with points pt 6 ps 1.4 lc rgb '#404040' title 'mode / setting', \\\n"
       << "     '' using 2:(atleast($3)):1 with labels left offset 0.8,0.6 notitle\n";
    if (r.streaming.frames > 0)
        gp << "set output " << gpQuote((dir / "resident_memory.png").string()) << "\n"
           << "set title " << gpQuote("Resident memory (" + title + ")") << "\nset xlabel 'frame'\nset ylabel 'MB'\n"
           << "unset logscale y\nset offsets 0, 0, 0, 0\nset yrange [0:*]\nset datafile separator ','\n"
           << "sdata = " << gpQuote((dir / "streaming.csv").string()) << "\n"
           << "plot sdata using 1:2 skip 1 with lines lw 2 title 'leaves in main memory', \\\n"
           << "     sdata using 1:3 skip 1 with lines lw 2 title 'leaves in GL buffers', \\\n"
           << "     sdata using 1:4 skip 1 with lines lw 2 title 'process resident set (RSS)'\n";
    if (Status s = closeChecked(gp, dir / "plots.gp"); !s) return skipped(s);
    const fs::path log = dir / "gnuplot.log";
    const std::string cmd = shellQuote(gnuplot) + " " + shellQuote((dir / "plots.gp").string()) + " > " +
                            shellQuote(log.string()) + " 2>&1";
    const int rc = std::system(cmd.c_str());
    for (const char* png :
         {"time_per_frame.png", "parts_per_frame.png", "queries_per_frame.png", "speed_vs_accuracy.png", "resident_memory.png"}) {
        std::error_code ec;
        if (fs::exists(dir / png, ec) && fs::file_size(dir / png, ec) > 0) out.pngs.push_back(png);
    }
    if (rc != 0) out.message = "gnuplot failed (see " + log.string() + ")";
    return out;
}

bool reportsVolumes(const BenchResult& r) {
    return std::any_of(r.modes.begin(), r.modes.end(),
                       [](const ModeSpec& m) { return queriesNodeVolumes(m) && m.scheduler.tuning.volume != SchedulerParams{}.tuning.volume; });
}

namespace {

/// Compact engineering notation for large totals (e.g. 1.23e+04).
std::string sci(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

void writeVolumeTable(std::ofstream& f, const std::vector<ModeSummary>& summary) {
    double best = 0;
    for (const ModeSummary& s : summary)
        if (!s.volume.empty() && (best == 0 || s.msMean < best)) best = s.msMean;
    f << "\n## Query volumes\n\n"
      << "Per mode that queries node volumes (the k-DOP paper's Tables 2 and 5): time, culling, queries, and the "
         "world-space total volume and surface area of the query volumes of all object parts (local-BSP leaves) at "
         "the last frame.\n\n"
      << "| mode | volume | ms/frame | vs best | per-frame vs best | parts culled (% of vfc's) | parts drawn | queries | occluded |"
         " % occluded | triangles/query | leaf volume | leaf surface area | leaf triangles mean (max) |"
         " leaves aabb/obb/14/18/26 | false neg. (parts) |\n"
      << "|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|---|--:|\n";
    for (const ModeSummary& s : summary) {
        if (s.volume.empty()) continue;
        const LeafVolumeTotals& l = s.leaves;
        std::string kinds;
        for (std::size_t k = 0; k < l.leavesByKind.size(); ++k) kinds += (k ? "/" : "") + std::to_string(l.leavesByKind[k]);
        f << "| " << s.name << " | " << s.volume << " | " << fmt(s.msMean, 2) << " | " << fmt(best > 0 ? s.msMean / best : 0, 3)
          << " | " << fmt(s.pairedVsBest, 3) << " | " << fmt(s.pctPartsCulled, 1) << " | " << fmt(s.parts, 1) << " | " << fmt(s.queries, 1) << " | "
          << fmt(s.occluded, 1) << " | " << fmt(s.queries > 0 ? 100.0 * s.occluded / s.queries : 0.0, 1) << " | "
          << fmt(s.queries > 0 ? s.queryTriangles / s.queries : 0.0, 1) << " | " << sci(l.volume) << " | "
          << sci(l.surfaceArea) << " | "
          << fmt(l.leaves ? static_cast<double>(l.triangles) / static_cast<double>(l.leaves) : 0.0, 1) << " ("
          << l.maxTriangles << ") | " << kinds << " | " << s.falseNegatives << " |\n";
    }
    f << "\n*vs best*: mean ms over the fastest volume mode's; *per-frame vs best*: median over frames of the "
         "frame's ms over the fastest volume mode's ms in the same frame (robust to load changes on a shared "
         "machine); *parts culled*: parts vfc drew that this mode did not, "
         "over all frames; *triangles/query*: triangles of the query volumes per query issued (scene nodes and "
         "untightened objects are queried with 12-triangle world boxes); *leaves ...*: how many object parts got each "
         "kind (auto picks per part).\n";
}

/// The cheap tests of the modes that make them (two-phase's depth pyramid and batched raster test).
void writeCheapTestTable(std::ostream& f, const std::vector<ModeSummary>& summary) {
    if (std::none_of(summary.begin(), summary.end(), [](const ModeSummary& s) { return s.depthTests + s.rasterTests > 0; }))
        return;
    f << "\n## Cheap tests\n\n"
      << "| mode | pyramid builds | pyramid tests | raster tests | readback + pyramid ms | raster ms | µs per test | "
         "waiting for drawing ms | pyramid tests ms | µs per test, own cost | cluster pyramid tests | cluster ms | "
         "µs per test, own cost, clusters counted |\n"
      << "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n";
    for (const ModeSummary& s : summary) {
        const double tests = s.depthTests + s.rasterTests;
        if (tests <= 0) continue;
        f << "| " << s.name << " | " << fmt(s.pyramidBuilds, 2) << " | " << fmt(s.depthTests, 1) << " | " << fmt(s.rasterTests, 1)
          << " | " << fmt(s.depthReadMs, 2) << " | " << fmt(s.rasterMs, 2) << " | "
          << fmt(1000.0 * (s.depthReadMs + s.rasterMs) / tests, 2) << " | ";
        const double ownMs = s.depthReadMs + s.rasterMs - s.drawWaitMs + s.pyramidTestMs;
        if (s.drawWaitMs > 0.0)
            f << fmt(s.drawWaitMs, 2) << " | " << fmt(s.pyramidTestMs, 2) << " | " << fmt(1000.0 * ownMs / tests, 2) << " | ";
        else
            f << "n/a | n/a | n/a | ";
        f << fmt(s.clusterPyramidTests, 1) << " | " << fmt(s.clusterMs, 2) << " | ";
        if (s.drawWaitMs > 0.0)
            f << fmt(1000.0 * (ownMs + s.clusterMs) / (tests + s.clusterPyramidTests), 2) << " |\n";
        else
            f << "n/a |\n";
    }
    f << "\nPer frame. *Readback + pyramid ms*: reading the depth back (which waits for the drawing before it) and "
         "building the pyramid; *raster ms*: the batched raster tests, drawn and read back; *µs per test*: both over "
         "the pyramid and raster tests, so it counts the waits too. The last three columns only for `full-splitwaits`, "
         "which waits for the drawing apart before each read and test: *waiting for drawing ms* is that wait (part of "
         "the two before), *pyramid tests ms* the CPU of the pyramid tests (footprints and reads, in the traversal), "
         "and *own cost* readback, pyramid builds, raster tests and pyramid tests without the waits, over the tests. "
         "*Cluster pyramid tests*: clusters projected and compared with a pyramid (the late pass's, and cluster "
         "history's record against the final depth), volume tests as much as the parts' and served by the same "
         "reads and builds; *cluster ms*: all CPU in cluster selection and the record, their cone and frustum tests "
         "too (so the cost is overstated); *clusters counted*: own cost plus cluster ms, over all volume tests.\n";
}

void writeFalsePositiveTable(std::ostream& f, const BenchResult& r, const std::vector<ModeSummary>& summary) {
    double visibleTris = 0, aabbParts = 0, aabbTris = 0, autoParts = 0, autoTris = 0, visibleParts = 0;
    double clusterTris = 0, visibleClusterTris = 0, hiddenClusters = 0, hiddenTris = 0, hiddenSamples = 0, budgetTris = 0, budgetPixels = 0;
    std::size_t bounded = 0;
    for (const FrameTruth& t : r.truth) {
        if (!t.boundMeasured) continue;
        ++bounded;
        visibleParts += t.visibleParts;
        visibleTris += static_cast<double>(t.visibleTriangles);
        aabbParts += t.boundAabb.parts;
        aabbTris += static_cast<double>(t.boundAabb.triangles);
        autoParts += t.boundAuto.parts;
        autoTris += static_cast<double>(t.boundAuto.triangles);
        visibleClusterTris += static_cast<double>(t.visibleClusterTriangles);
        const ClusterBound& c = t.boundClusters;
        clusterTris += static_cast<double>(c.triangles);
        hiddenClusters += c.hiddenClusters;
        hiddenTris += static_cast<double>(c.hiddenTriangles);
        hiddenSamples += static_cast<double>(c.hiddenSamples);
        budgetTris += c.budgetTriangleBound;
        budgetPixels += static_cast<double>(c.budgetPixels);
    }
    f << "\n## Where the false positives come from\n\n"
      << "| mode | false pos./frame | query answered visible | history | occupancy accept | other untested | draw queries | of them drew nothing |\n"
      << "|---|--:|--:|--:|--:|--:|--:|--:|\n";
    for (const ModeSummary& s : summary) {
        if (s.oracle) continue;
        f << "| " << s.name << " | " << fmt(s.falsePositives, 1) << " | " << fmt(s.fpQueried, 1) << " | "
          << fmt(s.fpHistory, 1) << " | " << fmt(s.fpOccupancy, 1) << " | " << fmt(s.fpOther, 1) << " | "
          << fmt(s.drawQueries, 1) << " | " << fmt(s.drawQueriesOccluded, 1) << " |\n";
    }
    f << "\nPer frame: drawn parts with no visible pixel, by the decision that drew them (*other*: near plane, "
         "front-most leaves, or vfc). *Draw queries*: parts drawn untested inside a query on their geometry; "
         "*drew nothing*: answers read the next frame that found no sample (those parts are queried again).\n";
    if (bounded == 0) return;
    const double n = static_cast<double>(bounded);
    f << "\n**Volume bound** (`--volume-bound`, " << bounded << " frames): parts whose query volume passes a query "
      << "against the frame's final depth — what a conservative query-based mode with that volume draws at least, "
      << "with perfect order and no history. Visible parts (the oracle): " << fmt(visibleParts / n, 1) << " per frame, "
      << fmt(visibleTris / n, 0) << " triangles.\n\n"
      << "| volume | parts/frame | triangles/frame | triangles vs oracle |\n|---|--:|--:|--:|\n"
      << "| aabb (transformed local boxes) | " << fmt(aabbParts / n, 1) << " | " << fmt(aabbTris / n, 0) << " | "
      << fmt(visibleTris > 0 ? aabbTris / visibleTris : 0.0, 3) << " |\n"
      << "| auto (k-DOPs where they pay) | " << fmt(autoParts / n, 1) << " | " << fmt(autoTris / n, 0) << " | "
      << fmt(visibleTris > 0 ? autoTris / visibleTris : 0.0, 3) << " |\n"
      << "\n**Cluster-box bound**: every cluster that does not face away and whose box passes the batched raster "
      << "test against the final depth, of the parts whose box, PCA box and 26-DOP all pass too (parts without "
      << "clusters: the part). Per frame: "
      << fmt(clusterTris / n, 0) << " triangles (the visible clusters hold " << fmt(visibleClusterTris / n, 0)
      << "); of them " << fmt(hiddenClusters / n, 1) << " boxes own no pixel, with " << fmt(hiddenTris / n, 0)
      << " triangles and " << fmt(hiddenSamples / n, 0) << " box samples. An error budget of "
      << fmt(budgetPixels / n, 0) << " pixels spent on box samples (of clusters or whole parts) leaves out at most "
      << fmt(budgetTris / n, 0) << " triangles a frame.\n";
}

void writeClaimTable(std::ostream& f, const std::vector<ModeSummary>& summary) {
    // Only modes that cull approximately: they claim something, or act without a bound.
    bool any = false;
    for (const ModeSummary& s : summary) any |= s.claimedPctMax > 0 || s.framesUnbounded > 0;
    if (!any) return;
    f << "\n## Approximate settings: claimed error against measured\n\n"
      << "| mode | claimed % (mean) | claimed % (max) | lost % (max) | frames over claim (truth) | frames over claim "
         "(image) | frames without a bound | tied pixels | pop-in / frame |\n|---|--:|--:|--:|--:|--:|--:|--:|--:|\n";
    for (const ModeSummary& s : summary) {
        if (s.oracle || (s.claimedPctMax <= 0 && s.framesUnbounded == 0 && s.popIn <= 0)) continue;
        f << "| " << s.name << " | " << fmt(s.claimedPctMean, 4) << " | " << fmt(s.claimedPctMax, 4) << " | "
          << fmt(s.lostPctMax, 4) << " | " << s.framesOverClaimTruth << " | " << s.framesOverClaimImage << " | "
          << s.framesUnbounded << " | " << s.tiedPixels << " | " << fmt(s.popIn, 1) << " |\n";
    }
    f << "\nThe claim is each frame's bound on the pixels its approximate decisions lost (the error budget's "
         "spend, the sample threshold's samples, small features' rectangles). *Lost* pixels are those unlike vfc "
         "where the ground truth's part was not drawn; *over claim (truth)* counts frames whose false-negative "
         "pixels exceeded the claim, *(image)* frames whose lost pixels did; *tied* pixels differ from vfc where "
         "nothing was lost (depth ties drawn in another order); frames *without a bound* culled on last frame's "
         "answers and claim nothing. Pop-in: parts missing in one frame and drawn in the next.\n";
}

void writeFrameRatioTable(std::ostream& f, const std::vector<ModeSummary>& summary) {
    if (std::none_of(summary.begin(), summary.end(), [](const ModeSummary& s) { return s.vfcRatioMedian > 0; })) return;
    f << "\n## Each frame against vfc\n\n"
      << "| mode | median | 95th percentile | worst (frame) |\n|---|--:|--:|--:|\n";
    for (const ModeSummary& s : summary)
        if (s.vfcRatioMedian > 0 && s.name != "vfc")
            f << "| " << s.name << " | " << fmt(s.vfcRatioMedian, 3) << " | " << fmt(s.vfcRatioP95, 3) << " | "
              << fmt(s.vfcRatioMax, 3) << " (" << s.vfcRatioMaxFrame << ") |\n";
    f << "\nA mode's ms over vfc's in the same frame, over frames 1 and up (frame 0 builds every mode's history); "
         "the 95th percentile is the nearest rank. `vfc-again`, where run, is vfc against itself: the noise floor "
         "of these ratios.\n";
}

}  // namespace

Status writeReport(const BenchResult& r, const std::vector<ModeSummary>& summary, const std::string& command,
                   const std::vector<std::string>& plots, const std::string& streaming, const fs::path& path) {
    std::ofstream f;
    if (Status s = openChecked(f, path); !s) return s;
    double visible = 0, frustum = 0, gtMs = 0, updateMs = 0;
    for (const FrameTruth& t : r.truth) {
        visible += t.visibleParts;
        frustum += t.frustumParts;
        gtMs += t.groundTruthMs;
        updateMs += t.updateMs;
    }
    const double n = std::max<double>(1.0, static_cast<double>(r.truth.size()));
    f << "# dyncull measurement: " << r.scene << "\n\n"
      << "`" << command << "`\n\n"
      << "- scene: " << r.description << "\n"
      << "- renderer: " << r.renderer << ", " << r.width << "x" << r.height << ", " << r.truth.size() << " frames\n"
      << "- ground truth (ID pass): " << fmt(visible / n, 1) << " visible parts per frame of " << fmt(frustum / n, 1)
      << " in the frustum; " << fmt(gtMs / n, 1) << " ms per frame, not counted in any mode\n"
      << "- loose-BSP relink: " << fmt(updateMs / n, 2) << " ms per frame, done once per frame before the modes "
      << "(not counted in any mode)\n"
      << "- modes run interleaved: per frame the scene moves once, then every mode renders that frame with its own "
         "scheduler and history, in an order rotated every frame (vfc's image, the reference, is compared after all are drawn)\n";
    if (r.passes > 1)
        f << "- times: each mode's least over " << r.passes << " passes of the frames, each from a fresh scene, engine and "
          << "schedulers (everything else from the first pass); " << r.passFramesApart
          << " mode-frames drew another triangle count in a later pass\n";
    if (!streaming.empty())
        f << "- geometry streamed (per frame in streaming.csv; all modes of a frame share the caches): `" << streaming
          << "`\n";
    f << "\n";
    f << "| mode | ms/frame | median | vs vfc | vs oracle | parts drawn | triangles | queries | occluded | sched ms | query ms | wait ms |"
         " % px wrong (mean) | % px wrong (max) | frames wrong | false neg. (parts) | false neg. (px) |"
         " false pos./frame | largest wrong region (px) | timeouts |\n"
      << "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|\n";
    for (const ModeSummary& s : summary)
        f << "| " << s.name << (s.pareto ? " *" : "") << " | " << fmt(s.msMean, 2) << " | " << fmt(s.msMedian, 2)
          << " | " << fmt(s.ratioVfc, 2) << " | " << fmt(s.ratioOracle, 2) << " | " << fmt(s.parts, 1) << " | "
          << fmt(s.triangles, 0) << " | " << fmt(s.queries, 1) << " | " << fmt(s.occluded, 1) << " | "
          << fmt(s.traversalMs, 2) << " | " << fmt(s.queryMs, 2) << " | " << fmt(s.waitMs, 2) << " | " << fmt(s.pctWrongMean, 4) << " | " << fmt(s.pctWrongMax, 4) << " | "
          << s.framesWrong << " | " << s.falseNegatives << " | " << s.falseNegativePixels << " | "
          << fmt(s.falsePositives, 1) << " | " << s.largestRegion << " | " << s.timeouts << " |\n";
    f << "\nColumns: means per frame unless noted; *vs vfc* and *vs oracle* are mean ms divided by that mode's; "
         "*sched ms* is CPU time in traversal and scheduling, *query ms* time inside the query backend (issuing "
         "volumes, polling; on llvmpipe a poll can flush the command stream), *wait ms* time blocked on a result; "
         "*% px wrong* compares the frame exactly (RGBA) with the vfc frame; false negatives are visible parts "
         "(ground truth) not drawn, summed over frames, with the pixels they own; false positives are drawn parts "
         "with no visible pixel; the largest wrong region is the biggest 4-connected blob of wrong pixels in any "
         "frame. `*` marks modes on the speed-accuracy Pareto front (the oracle is a bound, not a mode).\n";
    writeFrameRatioTable(f, summary);
    writeFalsePositiveTable(f, r, summary);
    writeCheapTestTable(f, summary);
    writeClaimTable(f, summary);
    if (reportsVolumes(r)) writeVolumeTable(f, summary);
    if (!plots.empty()) {
        f << "\n## Plots\n\n";
        for (const std::string& p : plots) f << "![" << p << "](" << p << ")\n\n";
    }
    return closeChecked(f, path);
}

}  // namespace dyncull::cli
