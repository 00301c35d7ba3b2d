// `dyncull export SOURCE --out FILE.ply [--copies N]`: writes a static scene (the power
// plant, the city, a model file or a directory of parts) as one binary PLY, optionally as
// a row of N copies: the large models of the out-of-core benchmark (a 38M-triangle "plant
// campus" from three plants) without downloading any.
#include <cstdio>
#include <memory>
#include <string>

#include "cli_util.hpp"
#include "commands.hpp"
#include "dyncull/demos/demo_scene.hpp"
#include "dyncull/demos/progress_bar.hpp"
#include "dyncull/loaders/ply_stream.hpp"
#include "scene_options.hpp"

namespace dyncull::cli {
namespace {

struct ExportOptions {
    std::string source;
    std::string out;
    std::uint32_t copies = 1;
    SceneOptions sceneOptions;
};

void runExport(const ExportOptions& o) {
    Stopwatch sw;
    auto soup = loadStaticSoup(o.source, o.sceneOptions);
    if (!soup) fail(soup.error().message);
    const Mesh& m = soup->mesh;
    Aabb box;
    for (const glm::vec3& p : m.positions) box.extend(p);
    // Copies in a row along x, a tenth of the model's width apart.
    const float step = 1.1f * (box.max.x - box.min.x);
    const std::uint64_t v = m.positions.size(), t = m.triangleCount();
    if (v * o.copies > 0xFFFFFFFFull) fail("--copies " + std::to_string(o.copies) + ": more than 2^32 - 1 vertices");
    if (Status st = ensureParentDirectory(o.out); !st) fail(st.message());
    PlyWriter w;
    const bool normals = m.normals.size() == m.positions.size();
    if (Status st = w.open(o.out, v * o.copies, t * o.copies, normals,
                           "dyncull export " + o.source + " --copies " + std::to_string(o.copies));
        !st)
        fail(st.message());
    ProgressBar bar("writing " + o.out, static_cast<double>((v + t) * o.copies));
    for (std::uint32_t c = 0; c < o.copies; ++c) {
        const glm::vec3 offset(step * static_cast<float>(c), 0.0f, 0.0f);
        for (std::size_t i = 0; i < v; ++i)
            if (Status st = w.vertex(m.positions[i] + offset, normals ? m.normals[i] : glm::vec3(0.0f)); !st) fail(st.message());
        bar.advance(static_cast<double>(v));
    }
    for (std::uint32_t c = 0; c < o.copies; ++c) {
        const auto base = static_cast<std::uint32_t>(v * c);
        for (std::size_t i = 0; i < t; ++i)
            if (Status st = w.triangle(base + m.indices[3 * i], base + m.indices[3 * i + 1], base + m.indices[3 * i + 2]); !st)
                fail(st.message());
        bar.advance(static_cast<double>(t));
    }
    if (Status st = w.close(); !st) fail(st.message());
    bar.finish();
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(o.out, ec);
    std::printf("wrote %s: %u x %llu triangles, %.1f MB, in %.1f s\n", o.out.c_str(), o.copies,
                static_cast<unsigned long long>(t), ec ? 0.0 : static_cast<double>(bytes) / (1024.0 * 1024.0),
                sw.lap() / 1000.0);
}

}  // namespace

void registerExport(CLI::App& app) {
    auto o = std::make_shared<ExportOptions>();
    CLI::App* cmd = app.add_subcommand("export", "Write a static scene as one binary PLY (e.g. a large model for out-of-core runs)");
    cmd->add_option("source", o->source, "powerplant, city, a model file or a directory of .ply/.obj parts")->required();
    cmd->add_option("--out", o->out, "output .ply file")->required();
    cmd->add_option("--copies", o->copies, "copies in a row along x")->check(wholeIn(1, 64))->capture_default_str();
    addGeneratorOptions(*cmd, o->sceneOptions);
    cmd->callback([o] { runExport(*o); });
}

}  // namespace dyncull::cli
