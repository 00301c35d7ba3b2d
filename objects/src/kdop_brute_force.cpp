// Brute-force vertices of a k-DOP (the tests' oracle for kdopBoundary): every triple of
// bounding planes, solved by Cramer's rule, kept when inside all planes.
// Paper: kdop-bounding-volumes-for-occlusion.txt, section 3.3 (the k-DOP as the
// intersection of its k bounding planes).
#include <cmath>

#include "dyncull/objects/kdop.hpp"

namespace dyncull {

std::vector<glm::dvec3> kdopVerticesBruteForce(const Kdop& k, double tol) {
    const std::vector<KdopPlane> planes = kdopPlanes(k);
    std::vector<glm::dvec3> out;
    const std::size_t n = planes.size();
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j)
            for (std::size_t l = j + 1; l < n; ++l) {
                const glm::dvec3 &a = planes[i].normal, &b = planes[j].normal, &c = planes[l].normal;
                const glm::dvec3 bc = glm::cross(b, c), ca = glm::cross(c, a), ab = glm::cross(a, b);
                const double det = glm::dot(a, bc);
                // Unit normals from the fixed set are either independent (|det| >= 1/6)
                // or dependent (det is rounding noise).
                if (std::abs(det) < 1e-9) continue;
                const glm::dvec3 x = (planes[i].offset * bc + planes[j].offset * ca + planes[l].offset * ab) / det;
                bool inside = true;
                for (const KdopPlane& p : planes)
                    if (glm::dot(p.normal, x) - p.offset > tol) {
                        inside = false;
                        break;
                    }
                if (!inside) continue;
                bool dup = false;
                for (const glm::dvec3& y : out)
                    if (glm::length(x - y) <= tol) {
                        dup = true;
                        break;
                    }
                if (!dup) out.push_back(x);
            }
    return out;
}

}  // namespace dyncull
