// Camera auto: a camera that frames the head and its hair from a
// three-quarter view, fitted so that everything the frame must hold lies
// inside the picture with a margin (render.camera.mode: auto / follow).
//
// What must stay in the picture is given as spheres: the head's vertices
// (radius 0) and, for the hair, the scalp's vertices grown by the hair's
// reach (every hair point lies within its arc length of its root, and a
// root lies in a scalp triangle, whose grown hull is the hull of its grown
// vertices). The fit is exact for spheres against the frustum's four side
// planes, so the framing is conservative: no sphere, hence no head or hair
// pixel, reaches the border.
#pragma once

#include "render/view/view.h"

#include <Eigen/Geometry>

#include <array>
#include <vector>

namespace hp {

/// A sphere the picture must contain.
struct FramingSphere {
    Vec3f centre = Vec3f::Zero();
    float radius = 0.f;
};

/// What must stay in the picture at one frame, and the head's rigid motion
/// (for cut detection and the view direction).
struct FramingSample {
    int frame = 0;
    Eigen::Isometry3f head = Eigen::Isometry3f::Identity();  ///< head transform, rest -> this frame
    std::vector<FramingSphere> spheres;
};

struct FramingSettings {
    Vec3f facing{0.f, 0.f, 1.f};   ///< the head's front in its rest pose (glTF: +Z)
    Vec3f up{0.f, 1.f, 0.f};       ///< world up; the camera keeps it up on screen
    float azimuthDegrees = 35.f;   ///< camera turned from the face about `up` (35°: a three-quarter view)
    float elevationDegrees = 8.f;  ///< camera raised above the head's horizontal plane
    float margin = 0.06f;          ///< fraction of the half-frame kept empty at each border
    bool follow = false;           ///< frame each frame alone (else each cut-free segment as a whole)
    /// Cut detection: a jump of the head between two consecutive frames
    /// beyond these starts a new segment that is framed anew.
    float cutDistance = 0.1f;      ///< metres (head translation or bounds centre)
    float cutAngleDegrees = 45.f;  ///< head rotation
};

/// @brief The four vectors m (right, left, top, bottom side of the frame)
/// such that a sphere (P, r) constrains the fit of a camera looking along
/// -`direction` only through r + P·m: the sphere with the largest value
/// along each m is the one that touches that border. Hair read from the
/// strand cache needs only its extreme point along each m.
std::array<Vec3f, 4> framingNormals(const Camera& lens, const Vec3f& direction, const Vec3f& up, float margin);

/// @brief The camera with `lens`'s field of view, image size and clip planes,
/// looking along -`direction` (a unit vector from the subject toward the
/// camera) with `up` up, placed as close as possible with every sphere
/// inside the frustum shrunk by `margin` (of the half-frame, on each side).
/// @param spheres must not be empty.
Camera fitCamera(const Camera& lens, const Vec3f& direction, const Vec3f& up, float margin,
                 const std::vector<FramingSphere>& spheres);

/// @brief True when the head jumps between two consecutive frames: its rigid
/// transform moves by more than settings.cutDistance or turns by more than
/// settings.cutAngleDegrees, or the centre of its spheres' bounds moves by
/// more than cutDistance (a cut inside a vertex-animated clip). A small
/// function on purpose: a shot's own cut list (simulation.cut_*) can replace it.
bool isCut(const FramingSample& before, const FramingSample& after, const FramingSettings& settings);

/// @brief For each sample, the index of the first sample of its segment:
/// samples are cut into segments where isCut holds between neighbours.
/// `samples` are consecutive frames in increasing order.
std::vector<size_t> segmentStarts(const std::vector<FramingSample>& samples, const FramingSettings& settings);

/// @brief For each sample, the unit direction from the subject toward the
/// camera: the head's facing at its segment's first sample (flattened onto
/// the horizontal plane, so a nod does not tilt the shot), turned by the
/// azimuth about `up` and raised by the elevation.
std::vector<Vec3f> viewDirections(const std::vector<FramingSample>& samples, const std::vector<size_t>& starts,
                                  const FramingSettings& settings);

/// @brief One camera per sample (same order): each segment (`starts`, from
/// segmentStarts) is framed over all its samples (settings.follow: each
/// sample alone), seen from its viewDirections.
std::vector<Camera> frameSamples(const std::vector<FramingSample>& samples, const std::vector<size_t>& starts,
                                 const Camera& lens, const FramingSettings& settings);

}  // namespace hp
