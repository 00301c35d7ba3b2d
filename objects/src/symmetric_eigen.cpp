// Cyclic Jacobi eigenvalue algorithm for symmetric 3x3 matrices (Golub & Van Loan, 8.5;
// the rotation formulas of Numerical Recipes' jacobi). For PCA of OBBs:
// out-of-core-obb-depth-queries.txt, section 3. Jacobi is chosen over the closed-form
// cubic because it stays accurate for repeated and zero eigenvalues (planar, collinear
// and single-point sets), which the cubic's acos loses.
#include "dyncull/objects/symmetric_eigen.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace dyncull {

SymmetricEigen3 symmetricEigen3(const glm::dmat3& m) {
    // a[r][c] row-major working copy (glm is column-major: m[c][r]); symmetric from the upper triangle.
    double a[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = r; c < 3; ++c) a[r][c] = a[c][r] = m[c][r];
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

    SymmetricEigen3 out;
    double scale = 0.0;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) scale = std::max(scale, std::abs(a[r][c]));
    for (int sweep = 0; sweep < 50; ++sweep) {
        const double off = std::abs(a[0][1]) + std::abs(a[0][2]) + std::abs(a[1][2]);
        // Off-diagonal mass below double rounding of the largest entry: converged (also
        // ends at once for diagonal and zero matrices).
        if (!(off > 1e-15 * scale)) break;
        out.sweeps = sweep + 1;
        for (int p = 0; p < 2; ++p)
            for (int q = p + 1; q < 3; ++q) {
                const double apq = a[p][q];
                if (apq == 0.0) continue;
                // Rotation angle that zeroes a[p][q]: t = tan(phi), the smaller root.
                const double theta = (a[q][q] - a[p][p]) / (2.0 * apq);
                const double t = (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
                const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
                // A' = J^T A J with J the rotation in the (p, q) plane.
                for (int k = 0; k < 3; ++k) {
                    const double akp = a[k][p], akq = a[k][q];
                    a[k][p] = c * akp - s * akq;
                    a[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; ++k) {
                    const double apk = a[p][k], aqk = a[q][k];
                    a[p][k] = c * apk - s * aqk;
                    a[q][k] = s * apk + c * aqk;
                }
                a[p][q] = a[q][p] = 0.0;
                for (int k = 0; k < 3; ++k) {
                    const double vkp = v[k][p], vkq = v[k][q];
                    v[k][p] = c * vkp - s * vkq;
                    v[k][q] = s * vkp + c * vkq;
                }
            }
    }
    // Sort descending; the columns of v follow their eigenvalues.
    int order[3] = {0, 1, 2};
    std::sort(order, order + 3, [&](int i, int j) { return a[i][i] > a[j][j]; });
    for (int i = 0; i < 3; ++i) {
        out.values[i] = a[order[i]][order[i]];
        out.vectors[i] = glm::dvec3(v[0][order[i]], v[1][order[i]], v[2][order[i]]);
    }
    // Products of rotations are rotations, but sorting may have swapped two columns.
    if (glm::dot(glm::cross(out.vectors[0], out.vectors[1]), out.vectors[2]) < 0.0) out.vectors[2] = -out.vectors[2];
    return out;
}

}  // namespace dyncull
