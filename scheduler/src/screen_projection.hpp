// Conservative screen footprints of boxes and query volumes: the pixel rectangle a volume
// can touch and its nearest window depth, computed camera-relative in double, with the
// near plane handled on purpose (a volume reaching it is "crossing", never projected).
// Used by every mode's first visibility test, the depth-pyramid test and cluster culling.
#pragma once

#include <array>
#include <optional>

#include <glm/glm.hpp>

#include "dyncull/objects/aabb.hpp"
#include "dyncull/objects/camera.hpp"
#include "dyncull/scheduler/depth_pyramid.hpp"
#include "dyncull/scheduler/occupancy_map.hpp"
#include "dyncull/scheduler/query_backend.hpp"

namespace dyncull {

/// A volume's screen footprint, as the depth-pyramid tests read it.
struct DepthFootprint {
    /// The pixels it can touch, rounded outwards and padded by one: right for any sample
    /// pattern (a multisampled target's too).
    ScreenRect rect;
    /// The pixels whose centres it can cover: all of it that a single-sample depth buffer
    /// holds, and so all the depth pyramid (built only from such buffers) needs. Empty if
    /// it covers no pixel centre, and then it draws no fragment there.
    ScreenRect centres;
    float nearest = 1.0f;  ///< nearest window depth (reversed Z: the largest of its points')
    /// Its nearest depth pixel by pixel, bounded by its front faces' planes: set by boxDepth
    /// (none from volumeDepth); what DepthPyramid::occludedPerTexel reads.
    DepthPlanes planes;
    /// A box's footprint made without its planes and outline (boxDepth with `planes` off):
    /// `planes` is empty until it is made again with them, where a test needs them.
    bool planesLeftOut = false;
};

/// One object's matrix prepared for the footprints of many boxes in its object space (a
/// part's clusters): ScreenProjection::boxDepth's per-object terms, computed once. Double.
struct ObjectProjection {
    glm::dmat4 toWorld{1.0};  ///< object space to world space (for boxDepth the float matrix, exactly)
    /// Per axis i: how far the transformed box's two faces across axis i lie from its centre,
    /// per unit of the box's half extent along i (|det| / |column j x column k| of the
    /// matrix's linear part); 0 for a singular matrix.
    glm::dvec3 faceScale{0.0};
    /// Object space to clip space through the camera-relative view-projection, and to the
    /// distance along the view direction (clip w in perspective): a box's centre and half
    /// axes are projected by one product and three column scalings.
    glm::dmat4 toClip{1.0};
    glm::dvec4 toDistance{0.0};
    /// |toWorld|'s linear columns: a box's half axes' summed reach per world axis.
    glm::dmat3 absLinear{0.0};
    /// The eye in object space, which tells a box's front faces; not known for a singular
    /// matrix, whose boxes then get no DepthFootprint::planes.
    glm::dvec3 eyeLocal{0.0};
    bool eyeKnown = false;
};

/// A projected box's corners, kept by ScreenProjection::boxCentres for the front-face planes
/// it may be asked for afterwards (ScreenProjection::frontFacePlanes): most boxes a pyramid
/// test hides at once never need them.
struct BoxCorners {
    glm::dvec3 centre{0.0}, half{0.0};  ///< the box grown by its rounding, object space
    std::array<glm::dvec3, 8> window;   ///< corner i: NDC x, y and window depth
    bool valid = false;                 ///< false where the box was too thin for them
};

/// Projects world-space boxes and volumes into one frame's viewport (pixels, origin at the
/// lower left, as the occupancy maps and the depth pyramid count them). Borrows the view.
class ScreenProjection {
public:
    explicit ScreenProjection(const FrameView& view)
        : view_(view), distanceRow_(view.camera.distanceRowRelative()), world_(objectProjection(glm::mat4(1.0f))) {}

    /// The pixels world box `box` can touch, its part behind the near plane clipped away;
    /// false if the box reaches the near plane (within the rounding a GPU's float clipping
    /// may add), which makes it visible without a test. `out` is empty when nothing of the
    /// box is in front of the near plane or on screen.
    bool rect(const Aabb& box, ScreenRect& out) const;
    /// A query volume's footprint (pixel rectangles and nearest depth), the volume grown by
    /// its vertices' rounding first; false if it reaches the near plane (then it is simply
    /// visible).
    bool volumeDepth(const QueryVolume& volume, DepthFootprint& out) const;
    /// The identity prepared for boxDepth: world-space boxes.
    const ObjectProjection& worldProjection() const { return world_; }
    /// `matrix` (object to world) prepared for boxDepth.
    ObjectProjection objectProjection(const glm::mat4& matrix) const;
    /// The same for a matrix composed in double (an OBB's frame under its object's
    /// matrix), for frameBoxDepth.
    ObjectProjection objectProjection(const glm::dmat4& matrix) const;
    /// volumeDepth(QueryVolume::fromTransformedBox(matrix, local), out) for the matrix that
    /// `object` was prepared from, without building the volume: the box's centre and half
    /// axes are transformed once in double and its corners combined from them, and the
    /// faces' distances come from ObjectProjection::faceScale instead of the 12 triangles.
    /// The same margins for rounding, from the exact corners instead of their float
    /// roundings; a box too thin for them goes through volumeDepth.
    /// With `planes` off, the planes and outline are left out (DepthFootprint::planesLeftOut).
    bool boxDepth(const ObjectProjection& object, const Aabb& local, DepthFootprint& out, bool planes = true) const;
    /// boxDepth for a box whose matrix is no float matrix (`object` from the dmat4
    /// objectProjection): the same footprint, planes and outline, with the same margins for
    /// rounding. A box too thin for those margins is left to the caller, who knows its float
    /// vertices (std::nullopt); otherwise false if it reaches the near plane.
    std::optional<bool> frameBoxDepth(const ObjectProjection& object, const Aabb& local, DepthFootprint& out, bool planes = true) const;
    /// boxDepth's `centres` and `nearest` alone, all a depth-pyramid test reads (the
    /// clusters' test, by the tens of thousands a frame).
    /// With `corners`, also what its front faces' planes are computed from (frontFacePlanes).
    bool boxCentres(const ObjectProjection& object, const Aabb& local, ScreenRect& centres, float& nearestDepth,
                    BoxCorners* corners = nullptr) const;
    /// The planes of the front faces of a box that boxCentres kept `corners` of, projected
    /// with `object` (DepthFootprint::planes), and its outline; none if the corners are not
    /// valid.
    void frontFacePlanes(const ObjectProjection& object, const BoxCorners& corners, DepthPlanes& out) const;
    /// A guess, for choices that need no guarantee (cluster history's record of what
    /// showed): the pixels whose centres box `local` under `objectToClip` (object space to
    /// clip space, camera-relative: clipMatrixOf) covers and its nearest window depth, its 8
    /// corners projected in float with no rounding margins; false if a corner lies behind
    /// the near plane.
    bool roughBoxDepth(const glm::mat4& objectToClip, const Aabb& local, ScreenRect& centres, float& nearestDepth) const;
    /// Object space to clip space for an object whose object-to-world matrix is `matrix`,
    /// through the camera-relative view-projection (in double, then float).
    glm::mat4 clipMatrixOf(const glm::mat4& matrix) const;
    /// Normalised-device bounds [lo, hi] as viewport pixels, rounded outwards, padded by one.
    ScreenRect pixelRect(const glm::dvec2& lo, const glm::dvec2& hi) const;
    /// The viewport pixels whose centres normalised-device bounds [lo, hi] can cover.
    ScreenRect centreRect(const glm::dvec2& lo, const glm::dvec2& hi) const;

private:
    /// The outline of a box in front of the eye from its projected corners (DepthPlanes::edges).
    void outline(const std::array<glm::dvec3, 8>& corners, DepthPlanes& out) const;
    /// The distance along the view direction of eye-relative point `rel` whose clip
    /// coordinates are `clip`: clip w in perspective, along distanceRow_ in orthographic.
    double viewDistance(const glm::dvec4& clip, const glm::dvec3& rel) const {
        return view_.camera.orthographic() ? glm::dot(distanceRow_, glm::dvec4(rel, 1.0)) : clip.w;
    }

    enum class BoxNdc : std::uint8_t { InFront, Crossing, Thin };
    /// boxDepth's corners in normalised device coordinates: their bounds and nearest window
    /// depth (InFront), a box reaching the near plane (Crossing), or one too thin for the
    /// margins of its centre-and-axes form (Thin: left to volumeDepth).
    /// With `corners`, also the (grown) box and its corners' window coordinates, for its
    /// front faces' planes (frontFacePlanes), where it is in front.
    BoxNdc boxNdc(const ObjectProjection& object, const Aabb& local, glm::dvec2& ndcLo, glm::dvec2& ndcHi, double& nearestDepth,
                  BoxCorners* corners = nullptr) const;
    /// The footprint of the eye-relative points `rel[0, n)`, which already hold their margins.
    bool pointsDepth(const glm::dvec3* rel, std::uint32_t n, DepthFootprint& out) const;

    const FrameView& view_;
    glm::dvec4 distanceRow_;  // Camera::distanceRowRelative
    ObjectProjection world_;  // worldProjection
};

}  // namespace dyncull
