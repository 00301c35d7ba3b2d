// Internal (objects): vertices that share a position, as one topological vertex.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace dyncull::detail {

/// Welded id per vertex: equal float bits (after -0 -> +0) give one id; ids are dense from
/// 0 in first-seen order and `weldedCount` is set to their number. Loaders duplicate
/// vertices at normal and UV seams, which must not read as holes. O(n) expected.
std::vector<std::uint32_t> weldVertices(const std::vector<glm::vec3>& pos, std::size_t& weldedCount);

}  // namespace dyncull::detail
