// `dyncull subdivide SOURCE --method phbvo|dbvs|octree|grid --max-tris N --out FILE`:
// cuts a static model (a model file, a directory of parts, or the power plant / city
// merged into one soup) into subdivision entities and saves it for `dyncull run/bench
// FILE`. Prints the tree's size, the build time and the memory used while subdividing.
// Paper: Scene subdivision for occlusion culling, section 3.
// With --memory-mb N it builds a streamed model (FILE.dnodes + FILE.dgeom) out of core
// instead, never holding the whole model: a PLY source is streamed from disk.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "cli_util.hpp"
#include "commands.hpp"
#include "dyncull/bsp/subdivision_file.hpp"
#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/demos/progress_bar.hpp"
#include "dyncull/loaders/ply_stream.hpp"
#include "dyncull/objects/file_extension.hpp"
#include "dyncull/streaming/out_of_core_subdivision.hpp"
#include "scene_options.hpp"

namespace dyncull::cli {
namespace {

struct SubdivideCommandOptions {
    std::string source;
    std::string out;
    std::uint32_t memoryMb = 0;  // > 0: out of core under this budget
    std::string tempDir;
    SceneOptions sceneOptions;
};

/// Resets the peak resident size (VmHWM) to the current one (Linux >= 4.0); false if unavailable.
bool resetPeakRss() {
    std::ofstream f("/proc/self/clear_refs");
    f << "5";
    return static_cast<bool>(f);
}

double mb(std::size_t bytes) { return static_cast<double>(bytes) / (1024.0 * 1024.0); }

/// Out of core: a PLY file is streamed from disk; other sources (built-in scenes, OBJ,
/// glTF, directories) are loaded whole first, then streamed from memory.
void runSubdivideOutOfCore(const SubdivideCommandOptions& o) {
    auto sp = toSubdivisionParams(o.sceneOptions.subdivide);
    if (!sp) fail(sp.error().message);
    if (lowercaseExtension(o.out) != ".dnodes") fail("--out " + o.out + ": a streamed model is named BASE.dnodes (with BASE.dgeom beside it)");
    OutOfCoreParams params;
    params.subdivision = *sp;
    params.memoryBytes = std::size_t{o.memoryMb} << 20;
    params.tempDirectory = o.tempDir;
    Stopwatch sw;
    std::optional<StaticSoup> soup;
    MeshStreamSource source;
    if (lowercaseExtension(o.source) == ".ply") {
        params.source = o.source;
        source = [&](MeshStreamSink& sink) { return streamPly(o.source, sink); };
    } else {
        auto loaded = loadStaticSoup(o.source, o.sceneOptions);
        if (!loaded) fail(loaded.error().message);
        soup = loaded.take();
        params.source = soup->source;
        params.sourceHash = soup->sourceHash;
        source = meshSource(soup->mesh);
        std::printf("%s: not a PLY file, loaded whole (%zu triangles) in %.1f s, then streamed from memory\n",
                    o.source.c_str(), soup->mesh.triangleCount(), sw.lap() / 1000.0);
    }
    if (Status st = ensureParentDirectory(o.out); !st) fail(st.message());
    std::optional<ProgressBar> bar;
    std::string phase;
    double shown = 0.0;
    const OutOfCoreProgress progress = [&](const char* name, double done, double total) {
        if (phase != name) {
            phase = name;
            shown = 0.0;
            if (!bar) bar.emplace(name, total);
            else bar->restart(name, total);
        }
        bar->advance(done - shown);
        shown = done;
    };
    auto stats = subdivideOutOfCore(source, o.out, params, progress);
    if (bar) bar->finish();
    if (!stats) fail(o.source + ": " + stats.error().message);
    const OutOfCoreStats& s = *stats;
    const double seconds = sw.lap() / 1000.0;
    std::printf("%s: %llu vertices, %llu polygons, %llu triangles; normals %s\n", o.source.c_str(),
                static_cast<unsigned long long>(s.vertices), static_cast<unsigned long long>(s.polygons),
                static_cast<unsigned long long>(s.triangles), s.normalsFromSource ? "from the file" : "computed");
    std::printf("tree: %u nodes, %u leaves; %u streamed splits, %u subtrees built in memory (largest %llu triangles, "
                "limit %llu)\n",
                s.nodes, s.leaves, s.streamedSplits, s.memorySubtrees, static_cast<unsigned long long>(s.largestSubtree),
                static_cast<unsigned long long>(s.subtreeLimit));
    std::printf("time: %.1f s (reading %.1f, triangulating %.1f, subdividing %.1f)\n", seconds, s.readMs / 1000.0,
                s.triangulateMs / 1000.0, s.buildMs / 1000.0);
    std::printf("memory: budget %u MB, peak resident %.1f MB; vertex cache %.2f%% misses of %llu lookups; "
                "temporary files %.1f MB written, %.1f MB read\n",
                o.memoryMb, mb(procStatusBytes("VmHWM:")),
                s.cacheLookups ? 100.0 * static_cast<double>(s.cacheMisses) / static_cast<double>(s.cacheLookups) : 0.0,
                static_cast<unsigned long long>(s.cacheLookups), mb(s.tempBytesWritten), mb(s.tempBytesRead));
    std::printf("wrote %s and %s (%.1f MB of geometry)\n", o.out.c_str(), geometryPathFor(o.out).c_str(),
                mb(s.geometryBytes));
}

void runSubdivide(const SubdivideCommandOptions& o) {
    if (o.memoryMb > 0) return runSubdivideOutOfCore(o);
    auto params = toSubdivisionParams(o.sceneOptions.subdivide);
    if (!params) fail(params.error().message);
    Stopwatch sw;
    auto soup = loadStaticSoup(o.source, o.sceneOptions);
    if (!soup) fail(soup.error().message);
    const Mesh& mesh = soup->mesh;
    const std::size_t meshBytes = mesh.positions.size() * sizeof(glm::vec3) + mesh.normals.size() * sizeof(glm::vec3) +
                                  mesh.indices.size() * sizeof(std::uint32_t);
    std::printf("%s: %zu triangles, %zu vertices, mesh %.1f MB, loaded in %.1f s\n", o.source.c_str(),
                mesh.triangleCount(), mesh.vertexCount(), mb(meshBytes), sw.lap() / 1000.0);
    std::fflush(stdout);
    const std::size_t rssBefore = procStatusBytes("VmRSS:");
    const bool peakReset = resetPeakRss();

    SubdividedModel model;
    model.mesh = std::move(soup->mesh);
    model.source = soup->source;
    model.sourceHash = soup->sourceHash;
    model.params = *params;
    auto sub = subdivide(model.mesh, model.params);
    if (!sub) fail(o.source + ": " + sub.error().message);
    model.subdivision = sub.take();
    const double subdivideMs = sw.lap();
    const std::size_t peak = procStatusBytes("VmHWM:");
    applyTriangleOrder(model.mesh, model.subdivision);
    const SubdivisionStats& s = model.subdivision.stats;
    std::printf("%s: %u nodes (%u inner, %u leaves), deepest leaf %u, largest leaf %u triangles (%u above the limit), "
                "at most %u children per node\n",
                toString(params->method), s.nodes, s.inner, s.leaves, s.depth, s.largestLeaf, s.oversizedLeaves,
                s.maxChildren);
    std::printf("time: %.2f s subdividing on %u threads\n", subdivideMs / 1000.0, params->threads);
    std::printf("memory: work arrays %.1f MB (%.2fx the mesh)", mb(s.workBytes),
                static_cast<double>(s.workBytes) / static_cast<double>(std::max<std::size_t>(meshBytes, 1)));
    if (peakReset && peak >= rssBefore) {
        // The process held more than the mesh before (code, loader leftovers); what
        // subdividing costs is the mesh plus the growth of the resident set.
        const std::size_t added = peak - rssBefore;
        std::printf("; resident %.1f MB before, peak %.1f MB while subdividing: mesh + %.1f MB = %.2fx the mesh",
                    mb(rssBefore), mb(peak), mb(added),
                    static_cast<double>(meshBytes + added) / static_cast<double>(std::max<std::size_t>(meshBytes, 1)));
    }
    std::printf("\n");
    if (Status st = ensureParentDirectory(o.out); !st) fail(st.message());
    if (Status st = writeSubdivisionFile(o.out, model); !st) fail(st.message());
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(o.out, ec);
    std::printf("wrote %s (%.1f MB) in %.1f s\n", o.out.c_str(), ec ? 0.0 : mb(bytes), sw.lap() / 1000.0);
}

}  // namespace

void registerSubdivide(CLI::App& app) {
    auto o = std::make_shared<SubdivideCommandOptions>();
    o->sceneOptions.subdivide.method = "phbvo";
    CLI::App* cmd = app.add_subcommand(
        "subdivide", "Cut a static model into objects (p-HBVO, D-BVS, octrees) and save it for run/bench");
    cmd->add_option("source", o->source, "a model file, a directory of .ply/.obj parts, or powerplant / city (merged into one soup)")
        ->required();
    cmd->add_option("--out", o->out, "output file (.dsub), read by `dyncull run/bench FILE`; with --memory-mb, BASE.dnodes")
        ->required();
    cmd->add_option("--memory-mb", o->memoryMb,
                    "build out of core under this many MB (PLY sources stream from disk); writes BASE.dnodes + BASE.dgeom")
        ->check(wholeIn(16, 1 << 20));
    cmd->add_option("--temp-dir", o->tempDir, "with --memory-mb: where temporary files go (default: beside --out)");
    SubdivideOptions& s = o->sceneOptions.subdivide;
    cmd->add_option("--method", s.method, "phbvo, dbvs, octree (load-balanced) or grid (regular octree)")->capture_default_str();
    cmd->add_option("--max-tris", s.maxTriangles, "maximum triangles per leaf (object)")
        ->check(wholeIn(1, kMaxTriangleCount))
        ->capture_default_str();
    cmd->add_option("--max-depth", s.maxDepth, "maximum subdivision depth")->check(wholeIn(1, kSubdivisionMaxDepth))->capture_default_str();
    cmd->add_option("--collapse", s.collapseTo, "collapse to at most this many children per node (4: quad tree; 0 keeps the tree)")
        ->check(wholeIn(0, 1000000))
        ->capture_default_str();
    cmd->add_option("--threads", s.threads, "worker threads (the result does not depend on it)")
        ->check(wholeIn(1, kMaxThreads))
        ->capture_default_str();
    addGeneratorOptions(*cmd, o->sceneOptions);
    cmd->callback([o] { runSubdivide(*o); });
}

}  // namespace dyncull::cli
