// Jacobi eigen-decomposition: A v = lambda v, orthonormal right-handed vectors, sorted
// values; diagonal, random, repeated, rank-one and zero matrices.
#include <gtest/gtest.h>

#include <random>

#include "dyncull/objects/symmetric_eigen.hpp"

using namespace dyncull;

namespace {

void expectDecomposes(const glm::dmat3& a, const SymmetricEigen3& e) {
    double norm = 0.0;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) norm = std::max(norm, std::abs(a[c][r]));
    const double tol = 1e-12 * std::max(norm, 1.0);
    for (int i = 0; i < 3; ++i) {
        const glm::dvec3 v = e.vectors[i];
        EXPECT_NEAR(glm::length(v), 1.0, 1e-12);
        const glm::dvec3 residual = a * v - e.values[i] * v;
        EXPECT_LT(glm::length(residual), tol) << "eigenpair " << i;
        for (int j = i + 1; j < 3; ++j) EXPECT_NEAR(glm::dot(v, glm::dvec3(e.vectors[j])), 0.0, 1e-12);
    }
    EXPECT_GE(e.values[0], e.values[1]);
    EXPECT_GE(e.values[1], e.values[2]);
    EXPECT_NEAR(glm::determinant(e.vectors), 1.0, 1e-12);
}

glm::dmat3 rotation(double ax, double ay) {
    const double cx = std::cos(ax), sx = std::sin(ax), cy = std::cos(ay), sy = std::sin(ay);
    const glm::dmat3 rx(1, 0, 0, 0, cx, sx, 0, -sx, cx), ry(cy, 0, -sy, 0, 1, 0, sy, 0, cy);
    return ry * rx;
}

}  // namespace

TEST(SymmetricEigen, DiagonalIsSortedAxes) {
    const glm::dmat3 a(3, 0, 0, 0, 1, 0, 0, 0, 2);
    const SymmetricEigen3 e = symmetricEigen3(a);
    EXPECT_DOUBLE_EQ(e.values[0], 3.0);
    EXPECT_DOUBLE_EQ(e.values[1], 2.0);
    EXPECT_DOUBLE_EQ(e.values[2], 1.0);
    EXPECT_NEAR(std::abs(e.vectors[0].x), 1.0, 1e-15);
    EXPECT_NEAR(std::abs(e.vectors[1].z), 1.0, 1e-15);
    EXPECT_EQ(e.sweeps, 0);
    expectDecomposes(a, e);
}

TEST(SymmetricEigen, RandomSymmetricMatrices) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-10.0, 10.0);
    for (int n = 0; n < 200; ++n) {
        glm::dmat3 a;
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r <= c; ++r) a[c][r] = a[r][c] = u(rng);
        const SymmetricEigen3 e = symmetricEigen3(a);
        expectDecomposes(a, e);
        EXPECT_LE(e.sweeps, 10);
    }
}

TEST(SymmetricEigen, RepeatedRankOneAndZero) {
    const glm::dmat3 r = rotation(0.7, -1.1);
    const glm::dmat3 repeated = r * glm::dmat3(2, 0, 0, 0, 5, 0, 0, 0, 2) * glm::transpose(r);
    SymmetricEigen3 e = symmetricEigen3(repeated);
    expectDecomposes(repeated, e);
    EXPECT_NEAR(e.values[0], 5.0, 1e-12);
    EXPECT_NEAR(e.values[1], 2.0, 1e-12);
    EXPECT_NEAR(e.values[2], 2.0, 1e-12);

    const glm::dvec3 d = glm::normalize(glm::dvec3(1, -2, 3));
    const glm::dmat3 rankOne = glm::outerProduct(d, d) * 4.0;  // collinear points' covariance
    e = symmetricEigen3(rankOne);
    expectDecomposes(rankOne, e);
    EXPECT_NEAR(std::abs(glm::dot(glm::dvec3(e.vectors[0]), d)), 1.0, 1e-12);
    EXPECT_NEAR(e.values[1], 0.0, 1e-12);

    e = symmetricEigen3(glm::dmat3(0.0));  // a single point's covariance
    EXPECT_EQ(e.values, glm::dvec3(0.0));
    EXPECT_EQ(e.vectors, glm::dmat3(1.0));

    const glm::dmat3 tiny = repeated * 1e-30, huge = repeated * 1e30;  // scale invariance
    expectDecomposes(tiny, symmetricEigen3(tiny));
    e = symmetricEigen3(huge);
    EXPECT_NEAR(e.values[0] / 1e30, 5.0, 1e-12);
}
