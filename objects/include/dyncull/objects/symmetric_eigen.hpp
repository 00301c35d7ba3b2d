// Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations, in double.
// Used by the PCA of oriented bounding boxes (out-of-core-obb-depth-queries.txt, section 3:
// the covariance matrix S factored as U^T L U).
#pragma once

#include <glm/glm.hpp>

namespace dyncull {

struct SymmetricEigen3 {
    glm::dvec3 values;   ///< eigenvalues, descending
    glm::dmat3 vectors;  ///< column i is the unit eigenvector of values[i]; a right-handed rotation
    int sweeps = 0;      ///< Jacobi sweeps used (at most 50)
};

/// Decomposes `a`, which must be symmetric (only the upper triangle is read). Repeated
/// eigenvalues get an arbitrary orthonormal basis of their eigenspace; the zero matrix
/// gives the identity. Non-finite input gives non-finite output (callers validate first).
SymmetricEigen3 symmetricEigen3(const glm::dmat3& a);

}  // namespace dyncull
