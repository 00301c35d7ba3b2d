// `dyncull inspect FILE`: builds the local BSP of every mesh in a file and prints, per
// mesh, triangles before and after splitting, leaves, depth and build time, and what the
// surface analysis says about culling its back faces.
#include <cstdio>
#include <memory>
#include <string>

#include "cli_util.hpp"
#include "commands.hpp"
#include "scene_options.hpp"
#include "dyncull/bsp/local_bsp.hpp"
#include "dyncull/loaders/loaders.hpp"
#include "dyncull/objects/surface_orientation.hpp"

namespace dyncull::cli {
namespace {

struct InspectOptions {
    std::string file;
    std::uint32_t maxLeafTriangles = LocalBspParams{}.maxLeafTriangles;
    std::uint32_t maxDepth = LocalBspParams{}.maxDepth;
    std::string method = "median";
    float nudge = LocalBspParams{}.nudgeFraction;
};

void runInspect(const InspectOptions& o) {
    LocalBspParams p;
    p.maxLeafTriangles = o.maxLeafTriangles;
    p.maxDepth = o.maxDepth;
    p.nudgeFraction = o.nudge;
    if (o.method == "median")
        p.method = SplitMethod::SpatialMedian;
    else if (o.method == "sah")
        p.method = SplitMethod::Sah;
    else
        fail("--method: unknown split method '" + o.method + "' (expected median or sah)");

    Stopwatch sw;
    auto scene = loadScene(o.file);
    if (!scene) fail(scene.error().message);
    std::printf("%s: %zu meshes, %zu instances, loaded in %.1f ms\n", o.file.c_str(), scene->meshes.size(),
                scene->instances.size(), sw.lap());
    if (scene->origin != glm::dvec3(0.0))
        std::printf("instances are relative to the scene origin (%.17g, %.17g, %.17g)\n", scene->origin.x,
                    scene->origin.y, scene->origin.z);
    std::printf("%-4s %-28s %10s %10s %7s %7s %6s %9s %8s  %s\n", "mesh", "name", "tris", "tris_after", "added%",
                "leaves", "depth", "build_ms", "surf_ms", "surface");
    std::size_t before = 0, after = 0, leaves = 0, cullBack = 0;
    double ms = 0, surfaceMs = 0;
    for (std::size_t i = 0; i < scene->meshes.size(); ++i) {
        const Mesh& m = scene->meshes[i];
        auto bsp = buildLocalBsp(m, p);
        if (!bsp) fail(o.file + ": mesh " + std::to_string(i) + ": " + bsp.error().message);
        const LocalBspStats& s = bsp->stats;
        const double added = s.trianglesBefore ? 100.0 * (double(s.trianglesAfter) / double(s.trianglesBefore) - 1.0) : 0.0;
        const SurfaceReport surface = analyseSurface(m);
        std::printf("%-4zu %-28.28s %10zu %10zu %7.2f %7u %6u %9.2f %8.2f  %s\n", i, m.name.c_str(), s.trianglesBefore,
                    s.trianglesAfter, added, s.leaves, s.depth, s.buildMs, surface.analyseMs, surface.summary().c_str());
        cullBack += surface.mode == FaceMode::CullBack;
        surfaceMs += surface.analyseMs;
        before += s.trianglesBefore;
        after += s.trianglesAfter;
        leaves += s.leaves;
        ms += s.buildMs;
    }
    std::printf("total: %zu triangles -> %zu (%+.2f%%), %zu leaves, %.1f ms building\n", before, after,
                before ? 100.0 * (double(after) / double(before) - 1.0) : 0.0, leaves, ms);
    std::printf("surfaces: %zu of %zu meshes may cull back faces, %zu two-sided; analysed in %.1f ms\n", cullBack,
                scene->meshes.size(), scene->meshes.size() - cullBack, surfaceMs);
}

}  // namespace

void registerInspect(CLI::App& app) {
    auto o = std::make_shared<InspectOptions>();
    CLI::App* cmd = app.add_subcommand("inspect", "Build and describe the local BSP of every mesh in a file");
    cmd->add_option("file", o->file, "Scene file (.ply .obj .gltf .glb)")->required();
    cmd->add_option("--max-leaf-tris", o->maxLeafTriangles, "Stop splitting at this many triangles")
        ->check(wholeIn(1, kMaxTriangleCount))
        ->capture_default_str();
    cmd->add_option("--max-depth", o->maxDepth, "Maximum tree depth")
        ->check(wholeIn(1, kLocalBspMaxDepth))
        ->capture_default_str();
    cmd->add_option("--method", o->method, "Split plane: median (spatial median, the paper's) or sah")->capture_default_str();
    cmd->add_option("--nudge", o->nudge, "Plane nudge window as a fraction of the node extent")
        ->check(realIn(0.0, 0.5))
        ->capture_default_str();
    cmd->callback([o] { runInspect(*o); });
}

}  // namespace dyncull::cli
