// Scene loading from files: PLY and Wavefront OBJ (own parsers) and
// glTF 2.0 (tinygltf). Every loader returns either a complete Scene or an Error whose
// one-line message starts with the file path and names the problem; it never returns a
// half-filled Scene. Every returned mesh has passed validateMesh(), is an indexed
// triangle list (polygons ear-clipped) and has unit normals (from the file when
// present and valid, otherwise computeNormals()).
#pragma once

#include <filesystem>

#include "dyncull/objects/error.hpp"
#include "dyncull/objects/scene.hpp"

namespace dyncull {

/// Dispatches on the extension (case-insensitive): .ply, .obj, .gltf, .glb.
/// Unknown extensions are an Error. The returned Scene owns all its data.
Expected<Scene> loadScene(const std::filesystem::path& path);

/// PLY in ascii, binary_little_endian or binary_big_endian. Needs a `vertex` element
/// with x, y, z and a `face` element with a `vertex_indices` (or `vertex_index`) list;
/// other elements and properties (confidence, intensity, flags, ...) are skipped.
/// Optional nx, ny, nz vertex properties are used as normals. Polygons are ear-clipped;
/// faces with fewer than 3 vertices and zero-area polygons are dropped. Arrays grow as
/// data is read, never from header counts. Result: one mesh, one identity instance;
/// units as in the file.
Expected<Scene> loadPly(const std::filesystem::path& path);

/// Wavefront OBJ. One mesh (and one identity instance) per OBJ shape (o/g group) that
/// has faces; vertices are deduplicated per mesh by (position, normal) index pair.
/// Materials and texture coordinates are ignored; a missing .mtl file is not an error.
/// Every number must parse and be finite, every index must name an element defined
/// earlier in the file, and a face needs 3 corners; otherwise the Error names the line.
/// Polygons are ear-clipped: zero-area ones are dropped, self-intersecting ones get
/// best-effort triangles.
Expected<Scene> loadObj(const std::filesystem::path& path);

/// glTF 2.0, .gltf (external or base64 buffers) or .glb. Walks the default scene (or
/// scene 0, or all root nodes when there is no scene): every node with a mesh becomes
/// an Instance whose transform is the node's world matrix (object -> world, glTF units,
/// usually metres), composed in double and stored relative to Scene::origin (non-zero
/// only for scenes far from the file's origin). Each glTF mesh used is loaded once into
/// one dyncull Mesh (its triangle, strip and fan primitives merged) and shared by all
/// nodes using it; point and line primitives are skipped. Reported as an Error: sparse
/// accessors, offsets/lengths/strides/counts outside their buffer, JSON nested deeper
/// than 64, GLB versions other than 2, unsupported required extensions (Draco included),
/// buffer URIs that are not regular files, node cycles, non-affine node matrices, and
/// nodes whose world matrix is non-finite or singular or places a mesh beyond
/// |coordinate| 1e15. Images are not decoded.
Expected<Scene> loadGltf(const std::filesystem::path& path);

}  // namespace dyncull
