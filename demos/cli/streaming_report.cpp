#include "streaming_report.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "cli_util.hpp"
#include "dyncull/objects/checked_write.hpp"

namespace dyncull::cli {
namespace {

double mb(double bytes) { return bytes / (1024.0 * 1024.0); }

}  // namespace

void StreamingSummary::add(std::uint64_t frame, const StreamingFrameStats& s, double frameMs) {
    rows.push_back({frame, s, frameMs, procStatusBytes("VmRSS:")});
    ++frames;
}

std::string StreamingSummary::line(const StreamOptions& o) const {
    double peakMem = 0, peakGpu = 0, read = 0, loads = 0, stall = 0, worstStall = 0;
    std::uint64_t hits = 0, misses = 0, late = 0, overflow = 0;
    for (const Row& r : rows) {
        peakMem = std::max(peakMem, static_cast<double>(r.s.memoryResidentBytes));
        peakGpu = std::max(peakGpu, static_cast<double>(r.s.gpuResidentBytes));
        read += static_cast<double>(r.s.bytesRead);
        loads += static_cast<double>(r.s.loads);
        stall += r.s.stallMs;
        if (&r != &rows.front()) worstStall = std::max(worstStall, r.s.stallMs);
        hits += r.s.hits;
        misses += r.s.misses;
        late += r.s.late;
        overflow += r.s.overflow;
    }
    const double n = static_cast<double>(std::max<std::uint64_t>(frames, 1));
    char buf[640];
    std::snprintf(buf, sizeof buf,
                  "streaming budget_mb=%u gpu_budget_mb=%u late=%s peak_resident_mb=%.1f peak_gpu_mb=%.1f peak_rss_mb=%.1f "
                  "read_mb_per_frame=%.2f loads_per_frame=%.1f hit_rate=%.4f (%llu of %llu) stall_ms_mean=%.2f "
                  "stall_ms_max_after_first=%.1f late_leaves=%llu overflow=%llu",
                  o.inCore ? 0u : o.memoryMb, o.inCore ? 0u : o.gpuMemoryMb, o.late.c_str(), mb(peakMem), mb(peakGpu),
                  mb(static_cast<double>(procStatusBytes("VmHWM:"))), mb(read) / n, loads / n,
                  hits + misses ? static_cast<double>(hits) / static_cast<double>(hits + misses) : 1.0,
                  static_cast<unsigned long long>(hits), static_cast<unsigned long long>(hits + misses), stall / n, worstStall,
                  static_cast<unsigned long long>(late), static_cast<unsigned long long>(overflow));
    return buf;
}

Status StreamingSummary::writeCsv(const std::filesystem::path& path) const {
    std::ostringstream f;
    f << "frame,resident_mb,gpu_resident_mb,rss_mb,read_mb,loads,evictions,gpu_evictions,uploads,hits,misses,stall_ms,late,"
         "overflow,frame_ms\n";
    for (const Row& r : rows)
        f << r.frame << ',' << mb(static_cast<double>(r.s.memoryResidentBytes)) << ','
          << mb(static_cast<double>(r.s.gpuResidentBytes)) << ',' << mb(static_cast<double>(r.rssBytes)) << ','
          << mb(static_cast<double>(r.s.bytesRead)) << ',' << r.s.loads << ',' << r.s.evictions << ',' << r.s.gpuEvictions
          << ',' << r.s.uploads << ',' << r.s.hits << ',' << r.s.misses << ',' << r.s.stallMs << ',' << r.s.late << ','
          << r.s.overflow << ',' << r.frameMs << '\n';
    return writeFileChecked(path, f.str());
}

}  // namespace dyncull::cli
