// Entry points of the scene generators and loaders behind the built-in scenes, exposed for
// tests (determinism, counts, cache keys) without going through an Engine.
#pragma once

#include <cstdint>
#include <string>

#include "dyncull/demos/demo_scene.hpp"
#include "prepared_scene.hpp"
#include "dyncull/demos/progress_bar.hpp"

namespace dyncull {

/// The power plant's meshes and placements (no local BSPs); `progress` may be null.
/// Errors for options out of range.
Expected<GeneratedScene> generatePowerPlant(const PowerPlantOptions& options, ProgressBar* progress);
/// Cache key: every option that changes geometry, plus the generator revision.
std::uint64_t powerPlantParamsHash(const PowerPlantOptions& options);

Expected<GeneratedScene> generateCity(const CityOptions& options, ProgressBar* progress);
std::uint64_t cityParamsHash(const CityOptions& options);

/// A static model made from a built-in scene ("powerplant", "city") flies that scene's
/// camera path: the scene (not populated) whose camera() gives it, null for other sources.
std::unique_ptr<DemoScene> builtinCameraScene(const std::string& source, const SceneOptions& options);
/// The generator parameter hash of a built-in source with `options`, 0 for other sources:
/// a model file made with other options would fly another path, so readers refuse it.
std::uint64_t builtinHash(const std::string& source, const SceneOptions& options);

/// Every .ply/.obj under `dir` (recursively, sorted by relative path), each file merged
/// into one mesh (instance transforms applied) placed as one static object with identity
/// transform. Errors name the first file that fails to load, or an empty directory.
Expected<GeneratedScene> loadSceneDir(const std::string& dir, ProgressBar* progress);

}  // namespace dyncull
