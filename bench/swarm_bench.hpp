// What the two frame-interleaved benches on the bunny swarm share (bench_draw_speed,
// bench_osg_peer): the swarm's command-line options, the variant record, the --only filter
// and the median. Each bench owns its variants and its frame loop.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/engine/image.hpp"

namespace dyncull::bench {

/// The bench's run: frames measured after one warm-up frame, the first frame of the swarm's
/// path, framebuffer size in pixels, output directory, variants kept (comma-separated; empty: all).
struct SwarmRun {
    std::uint32_t frames = 9, first = 0;
    int width = 640, height = 360;
    std::string out;
    std::string only;
};

/// Issue 21's swarm: 300 bunnies of size 1 in a box of side 8, orbited at 12.
inline BunnySwarmOptions issue21Swarm() {
    BunnySwarmOptions o;
    o.count = 300;
    o.box = 8.0f;
    o.bunnySize = 1.0f;
    o.speed = 0.02f;
    o.orbit = 12.0f;
    return o;
}

/// Adds the options both benches take; `size` receives --size as text (parseSize reads it).
inline void addSwarmOptions(CLI::App& app, BunnySwarmOptions& o, SwarmRun& run, std::string& size) {
    app.add_option("--frames", run.frames, "frames measured (every variant draws each)")->check(CLI::Range(1u, 100000u))->capture_default_str();
    app.add_option("--first", run.first, "first frame of the swarm's path")->capture_default_str();
    app.add_option("--count", o.count, "bunnies")->check(CLI::Range(1u, 100000u))->capture_default_str();
    app.add_option("--box", o.box, "side of the box they move in")->check(CLI::Range(0.01f, 1e6f))->capture_default_str();
    app.add_option("--bunny-size", o.bunnySize, "longest side of one bunny")->check(CLI::Range(0.001f, 1e5f))->capture_default_str();
    app.add_option("--speed", o.speed, "world units per frame")->check(CLI::Range(0.0f, 1e4f))->capture_default_str();
    app.add_option("--orbit", o.orbit, "orbit distance of the camera")->check(CLI::Range(0.01f, 1e7f))->capture_default_str();
    app.add_option("--mesh", o.meshPath, "mesh file instead of the asset directory's bunny");
    app.add_option("--size", size, "framebuffer WxH")->capture_default_str();
    app.add_option("--out", run.out, "output directory")->capture_default_str();
    app.add_option("--only", run.only, "comma-separated variants to run (default all)");
}

/// Reads --size into `run`; false if it is not WxH with both in [1, 16384].
inline bool parseSize(const std::string& size, SwarmRun& run) {
    int w = 0, h = 0;
    if (std::sscanf(size.c_str(), "%dx%d", &w, &h) != 2 || w < 1 || h < 1 || w > 16384 || h > 16384) return false;
    run.width = w;
    run.height = h;
    return true;
}

/// One way of drawing a frame, and what it measured.
struct Variant {
    std::string name;
    std::string what;
    std::function<std::uint64_t()> frame;  // draws one frame, returns triangles
    std::vector<double> ms;                // per measured frame
    std::uint64_t triangles = 0;           // of the last frame
    Image first;                           // the first measured frame's picture
};

/// Keeps the variants named in `only` (comma-separated; empty keeps all); false if none is left.
inline bool keepOnly(std::vector<Variant>& variants, const std::string& only) {
    if (only.empty()) return true;
    const std::string list = "," + only + ",";
    std::erase_if(variants, [&](const Variant& v) { return list.find("," + v.name + ",") == std::string::npos; });
    return !variants.empty();
}

inline double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace dyncull::bench
