// Built-in demo scenes and file scenes behind one interface, so `dyncull run`, `bench`,
// the tests and the benchmarks drive every scene the same way: populate an Engine once,
// then per frame move the objects and place the camera (both pure functions of the
// frame index, so every run and every mode sees the same frames).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dyncull/bsp/subdivision.hpp"
#include "dyncull/bsp/subdivision_file.hpp"
#include "dyncull/engine/engine.hpp"
#include "dyncull/engine/streamed_objects.hpp"
#include "dyncull/objects/camera.hpp"
#include "dyncull/objects/error.hpp"

namespace dyncull {

class DemoScene {
public:
    virtual ~DemoScene() = default;
    /// Short name used in stats and file names ("bunnies", "sponza_dabrovic", ...).
    virtual std::string name() const = 0;
    /// One or more lines saying what was loaded or generated (mesh used, counts).
    virtual std::string description() const = 0;
    /// Adds models and objects to `engine` (call once, on an empty engine).
    virtual Status populate(Engine& engine) = 0;
    /// Moves dynamic objects to their positions at `frame` (no-op for static scenes).
    virtual Status update(Engine& engine, std::uint64_t frame) = 0;
    /// Camera at `frame` for a viewport of aspect `aspect` (width / height).
    virtual Camera camera(std::uint64_t frame, float aspect) const = 0;
    /// Frames of the default camera path.
    virtual std::uint64_t defaultFrames() const = 0;
    /// Before each frame is rendered, with its camera (world space): a scene that streams
    /// its geometry starts reading ahead for it.
    virtual void beginFrame(const Camera& /*camera*/) {}
    /// After each frame is rendered (every mode and view of it): a streaming scene's
    /// counters for the frame, nothing for others. Error: a corrupt leaf met while drawing.
    virtual Expected<std::optional<StreamingFrameStats>> endFrame() { return std::optional<StreamingFrameStats>{}; }
    /// On while `bench` renders its reference image (vfc): a scene that may leave work
    /// out (streamed leaves not yet read, StreamLate::Draw or Skip) does it all then.
    virtual void setReferencePass(bool /*on*/) {}
    /// True for a scene whose reference pass changes what the passes after it find (it
    /// waits for streamed leaves, which stay read): `bench` then renders vfc first.
    virtual bool referencePassLoads() const { return false; }
    /// For ground truth: the world-space geometry an object (by slot) really has when its
    /// Engine model is only a box standing for it (streamed leaves); empty for scenes whose
    /// models are their geometry. The function fills the mesh and returns true for such
    /// an object, false for others.
    virtual std::function<bool(std::uint32_t objectSlot, Mesh&)> truthGeometry() { return {}; }
    /// Set-up time (loading, subdivision, local BSP builds), ms, filled by populate.
    double setupMs() const { return setupMs_; }

protected:
    double setupMs_ = 0.0;
};

/// Options of the bunny swarm; every one is a CLI option of `dyncull run bunnies`.
struct BunnySwarmOptions {
    std::uint32_t count = 300;
    float box = 9.0f;         ///< side of the cubic box the bunnies move in, world units (dense: bunnies overlap)
    float bunnySize = 1.6f;   ///< longest side of one bunny's bounding box, world units
    float speed = 0.03f;      ///< world units per frame
    std::uint64_t seed = 1;
    float orbit = 0.0f;       ///< > 0: orbit the box at this distance from its centre instead of the flight
    std::string meshPath;     ///< explicit mesh file; empty: search the asset directory
    std::string assetsDir;    ///< empty: $DYNCULL_ASSETS, else ./assets
    std::uint32_t frames = 400;  ///< frames of one pass along the default path
    /// Local-BSP leaf size (triangles). Smaller leaves cull finer but cost more queries;
    /// 5000 gives the two-level paper's 23-24 parts per bunny.
    std::uint32_t leafTriangles = LocalBspParams{}.maxLeafTriangles;
    /// Which faces are drawn (LocalBspParams::faces; Auto draws an open mesh two-sided).
    FacePolicy faces = LocalBspParams{}.faces;
    /// false: the mesh's holes are capped at load (capHoles), which closes a scanned solid
    /// such as the Stanford bunny (five holes in its base) so that Auto culls back faces.
    bool keepHoles = false;
    /// Triangles reordered inside each part for the vertex cache and overdraw (LocalBspParams::optimizeOrder).
    bool optimizeOrder = LocalBspParams{}.optimizeOrder;
    /// The cache order ends in meshlets (LocalBspParams::clusterOrder).
    bool clusterOrder = LocalBspParams{}.clusterOrder;
};

/// Where the bunny mesh comes from, in order: `meshPath`; `<assets>/bun_zipper.ply` (the
/// Stanford bunny, 69,451 triangles); `<assets>/bunny_npm.ply` (npm `bunny`, 3,674
/// triangles, public domain) refined by two levels of Loop subdivision (58,784).
struct BunnyMeshChoice {
    std::string path;
    bool subdivided = false;
};
Expected<BunnyMeshChoice> findBunnyMesh(const BunnySwarmOptions& options);

/// The bunny as the swarm hands it to its local BSP, before the split: loaded (findBunnyMesh),
/// subdivided if the choice says so, centred on the origin with its longest side
/// `options.bunnySize` (object space of every swarm instance), holes capped unless
/// `options.keepHoles`. What a peer renderer draws to show the same surface.
struct BunnyMesh {
    Mesh mesh;
    BunnyMeshChoice choice;
    std::size_t loadedTriangles = 0;      ///< as read from the file
    std::size_t subdividedTriangles = 0;  ///< after subdivision (= loadedTriangles without it)
    std::size_t holesCapped = 0;
    std::size_t cappingTriangles = 0;     ///< triangles the caps added
};
Expected<BunnyMesh> prepareBunnyMesh(const BunnySwarmOptions& options);

std::unique_ptr<DemoScene> makeBunnySwarm(const BunnySwarmOptions& options);

/// Any PLY/OBJ/glTF file as a static scene, with an automatic camera path: an orbit
/// outside for compact models, a walkthrough along the long axis for interiors.
std::unique_ptr<DemoScene> makeFileScene(const std::string& path);

/// The automatic camera of file scenes for a model with world box `bounds`: a walkthrough
/// or an orbit, at `frame` of a kStaticModelFrames-frame path, for a viewport of aspect `aspect`.
Camera staticModelCamera(const Aabb& bounds, bool walkthrough, std::uint64_t frame, float aspect);
/// Whether file scenes would walk through this model (world-space soup) or orbit it
/// (chooseFileCamera: elongated and enclosing). Copies the mesh; O(triangles x 96 rays).
bool staticModelWalkthrough(const Mesh& soup);
inline constexpr std::uint32_t kStaticModelFrames = 240;

/// Where generated scenes (power plant, city) cache their meshes and local BSPs.
struct SceneCacheOptions {
    std::string dir;       ///< empty: $DYNCULL_CACHE, else out/cache
    bool enabled = true;   ///< false: always generate, never read or write the cache
};

/// Procedural power plant in the size and character of the UNC Power Plant (about 1,200
/// objects, 12.7M triangles at size = detail = 1): a multi-storey hall with boilers, tanks,
/// pipe networks, girders, trusses, catwalks, stairs and machinery. Metres, Y up.
struct PowerPlantOptions {
    std::uint64_t seed = 1;
    float size = 1.0f;    ///< scales the number of objects (small values for tests), (0, 1]
    float detail = 1.0f;  ///< scales tessellation (segments around tubes, bend steps), (0, 1]
    std::uint32_t frames = 300;  ///< frames of the default flythrough
    unsigned threads = 2;        ///< worker threads for the local BSP builds
    SceneCacheOptions cache;
};

/// Procedural city: a grid of blocks with one closed building each (furniture-like clutter
/// on every floor behind the walls), streets, lamps and cars; street-level walk. Metres, Y up.
struct CityOptions {
    std::uint64_t seed = 1;
    std::uint32_t blocksX = 20, blocksZ = 20;  ///< 20 x 20 = 400 buildings
    std::uint32_t frames = 600;  ///< frames of the default walk
    unsigned threads = 2;
    SceneCacheOptions cache;
};

std::unique_ptr<DemoScene> makePowerPlant(const PowerPlantOptions& options);
std::unique_ptr<DemoScene> makeCity(const CityOptions& options);

/// Every .ply/.obj file under `dir` (recursively, sorted by relative path) as one static
/// object each, with an automatic camera (e.g. the UNC Power Plant's PLY parts).
std::unique_ptr<DemoScene> makeSceneDir(const std::string& dir);

/// Subdividing a static scene into objects on the fly (`--subdivide METHOD`); see
/// dyncull/bsp/subdivision.hpp for the methods.
struct SubdivideOptions {
    std::string method;  ///< phbvo, dbvs, octree or grid; empty: no subdivision
    std::uint32_t maxTriangles = SubdivisionParams{}.maxLeafTriangles;  ///< per leaf (object)
    std::uint32_t maxDepth = SubdivisionParams{}.maxDepth;
    std::uint32_t collapseTo = 0;  ///< > 0: at most this many children per node (4: quad tree)
    unsigned threads = 2;
};

/// Streaming a model larger than memory (`--memory-mb`): a .dnodes file, or a built-in
/// static scene preprocessed out of core on first use and cached.
struct StreamOptions {
    std::uint32_t memoryMb = 0;     ///< main-memory budget for leaf geometry; 0: not streamed
    std::uint32_t gpuMemoryMb = 64; ///< GL-buffer budget for leaf geometry; 0: no limit
    std::string late = "wait";      ///< StreamLate: wait, draw or skip
    /// The built-in scene whose camera path a streamed file flies ("powerplant", "city");
    /// empty: the file's own source decides, else the automatic camera of its bounds.
    std::string cameraOf;
    /// A .dnodes file read whole at start (every leaf resident, no budget): the in-core
    /// reference of the same objects and draws.
    bool inCore = false;
};

/// Options of every built-in scene, for makeScene.
struct SceneOptions {
    BunnySwarmOptions bunny;
    PowerPlantOptions plant;
    CityOptions city;
    SceneCacheOptions cache;  ///< copied into plant and city by makeScene
    std::string sceneDir;     ///< "powerplant" with a directory: load its PLY/OBJ parts instead
    SubdivideOptions subdivide;  ///< method set: static scenes are subdivided into objects
    StreamOptions stream;        ///< memoryMb set: static scenes stream their geometry
};

/// A static scene source as one triangle soup (instances applied): "powerplant" or "city"
/// (generated with `options`, every object merged), a directory of parts, or a model file.
/// `sourceHash` is the generator parameter hash of a built-in source, 0 for files.
struct StaticSoup {
    Mesh mesh;  ///< world space
    std::string source;
    std::uint64_t sourceHash = 0;
};
Expected<StaticSoup> loadStaticSoup(const std::string& nameOrPath, const SceneOptions& options);

/// Checks and converts SubdivideOptions (method name, ranges) to subdivision parameters.
Expected<SubdivisionParams> toSubdivisionParams(const SubdivideOptions& options);

/// Loads the soup of `nameOrPath` and subdivides it (triangle order applied to the mesh),
/// ready for writeSubdivisionFile or a SubdividedScene.
Expected<SubdividedModel> subdivideStaticScene(const std::string& nameOrPath, const SceneOptions& options);

/// A static scene subdivided into objects by options.subdivide on the fly: every leaf one
/// static object of the global loose BSP; the camera path is the source's own (built-in
/// scenes) or the automatic one of file scenes. Named "<source>_<method>".
std::unique_ptr<DemoScene> makeSubdividedScene(const std::string& nameOrPath, const SceneOptions& options);

/// A streamed model (`dyncull subdivide --memory-mb`, a .dnodes file) drawn under
/// options.stream's budgets; its leaves are static objects of the loose BSP.
std::unique_ptr<DemoScene> makeStreamedScene(const std::string& nodePath, const SceneOptions& options);
/// `powerplant` or `city` streamed: the .dnodes file in the scene cache, made on first use
/// by a child `dyncull subdivide --memory-mb` process (`exe`: this program), so this
/// process never holds the whole model.
Expected<std::unique_ptr<DemoScene>> makeStreamedBuiltin(const std::string& name, const SceneOptions& options,
                                                          const std::string& exe);

/// The same from a file written by `dyncull subdivide` (.dsub). A built-in source's
/// camera needs the generator options the file was made with: others are an error.
std::unique_ptr<DemoScene> makeSubdivisionFileScene(const std::string& path, const SceneOptions& options);

/// Resolves a scene argument: "bunnies", "powerplant", "city", a directory of PLY/OBJ
/// parts, or a model file.
Expected<std::unique_ptr<DemoScene>> makeScene(const std::string& nameOrPath, const SceneOptions& options);

/// Resolves a scene argument: "bunnies" (with `bunny` options) or a file path.
Expected<std::unique_ptr<DemoScene>> makeScene(const std::string& nameOrPath, const BunnySwarmOptions& bunny);

/// Names of the built-in scenes, for help texts.
std::vector<std::string> builtinSceneNames();

}  // namespace dyncull
