#include "render/view/camera_framing.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hp {

namespace {

constexpr float kDegrees = float(M_PI) / 180.f;

/// Unit vector from the subject toward the camera: the head's facing in the
/// world (flattened onto the horizontal plane, so a nod does not tilt the
/// shot), turned by the azimuth about `up` and raised by the elevation.
Vec3f viewDirection(const Eigen::Isometry3f& head, const FramingSettings& s) {
    const Vec3f up = s.up.normalized();
    Vec3f facing = head.linear() * s.facing.normalized();
    facing -= facing.dot(up) * up;
    if (facing.norm() < 1e-4f) {
        // Facing straight up or down: any horizontal direction will do.
        facing = up.unitOrthogonal();
    }
    facing.normalize();
    const Vec3f turned = Eigen::AngleAxisf(s.azimuthDegrees * kDegrees, up) * facing;
    const float e = s.elevationDegrees * kDegrees;
    return (std::cos(e) * turned + std::sin(e) * up).normalized();
}

Vec3f boundsCentre(const std::vector<FramingSphere>& spheres) {
    Eigen::AlignedBox3f box;
    for (const FramingSphere& s : spheres) box.extend(s.centre);
    return box.isEmpty() ? Vec3f(Vec3f::Zero()) : Vec3f(box.center());
}

}  // namespace

std::array<Vec3f, 4> framingNormals(const Camera& lens, const Vec3f& direction, const Vec3f& up, float margin) {
    const Vec3f f = (-direction).normalized();  // forward
    const Vec3f s = f.cross(up).normalized();   // screen right
    const Vec3f u = s.cross(f);                 // screen up
    // Half-angles of the frustum shrunk by the margin.
    const float keep = std::clamp(1.f - margin, 0.05f, 1.f);
    const float tanY = std::tan(0.5f * lens.fovY * kDegrees);
    const float a = std::atan(tanY * lens.aspect() * keep);  // horizontal
    const float b = std::atan(tanY * keep);                  // vertical
    // A sphere (centre P, radius r) is inside a side plane through the camera
    // c when its signed distance to the plane is >= r. With P and c in the
    // camera basis (x along s, z along f), the right plane x = z·tan(a) holds it when
    //   c_x·cos a − c_z·sin a >= r + P·(s cos a − f sin a),
    // the left plane x = −z·tan(a) when
    //  −c_x·cos a − c_z·sin a >= r + P·(−s cos a − f sin a),
    // and the same with u and b for the top and bottom.
    return {std::cos(a) * s - std::sin(a) * f, -std::cos(a) * s - std::sin(a) * f, std::cos(b) * u - std::sin(b) * f,
            -std::cos(b) * u - std::sin(b) * f};
}

Camera fitCamera(const Camera& lens, const Vec3f& direction, const Vec3f& up, float margin,
                 const std::vector<FramingSphere>& spheres) {
    if (spheres.empty()) throw Error("camera framing: nothing to frame");
    const std::array<Vec3f, 4> m = framingNormals(lens, direction, up, margin);
    // The largest right-hand side per plane (framingNormals): R, L, T, B.
    std::array<float, 4> most;
    most.fill(-std::numeric_limits<float>::infinity());
    for (const FramingSphere& sp : spheres)
        for (int k = 0; k < 4; ++k) most[k] = std::max(most[k], sp.radius + sp.centre.dot(m[k]));
    // Right and left both hold with equality at c_z = −(R + L) / (2 sin a),
    // c_x = (R − L) / (2 cos a); any c_z further back keeps both with c_x
    // unchanged. Same for top and bottom; the camera takes the farther c_z.
    const Vec3f f = (-direction).normalized();
    const Vec3f s = f.cross(up).normalized();
    const Vec3f u = s.cross(f);
    const float sinA = -m[0].dot(f), cosA = m[0].dot(s), sinB = -m[2].dot(f), cosB = m[2].dot(u);
    const float cz = std::min(-(most[0] + most[1]) / (2.f * sinA), -(most[2] + most[3]) / (2.f * sinB));
    const float cx = (most[0] - most[1]) / (2.f * cosA);
    const float cy = (most[2] - most[3]) / (2.f * cosB);

    Camera c = lens;
    c.position = cx * s + cy * u + cz * f;
    c.up = up;
    // Aim along f at the depth of the subject's centre (any point on the axis
    // gives the same view; this one keeps `target` meaningful).
    const float depth = std::max(boundsCentre(spheres).dot(f) - cz, 1e-3f);
    c.target = c.position + depth * f;
    return c;
}

bool isCut(const FramingSample& before, const FramingSample& after, const FramingSettings& settings) {
    const Eigen::Isometry3f step = after.head * before.head.inverse();
    const float moved = (after.head.translation() - before.head.translation()).norm();
    const float turned = Eigen::AngleAxisf(step.linear()).angle() / kDegrees;
    const float shifted = (boundsCentre(after.spheres) - boundsCentre(before.spheres)).norm();
    return moved > settings.cutDistance || shifted > settings.cutDistance || turned > settings.cutAngleDegrees;
}

std::vector<size_t> segmentStarts(const std::vector<FramingSample>& samples, const FramingSettings& settings) {
    std::vector<size_t> starts(samples.size(), 0);
    for (size_t i = 1; i < samples.size(); ++i)
        starts[i] = isCut(samples[i - 1], samples[i], settings) ? i : starts[i - 1];
    return starts;
}

std::vector<Vec3f> viewDirections(const std::vector<FramingSample>& samples, const std::vector<size_t>& starts,
                                  const FramingSettings& settings) {
    std::vector<Vec3f> directions(samples.size());
    for (size_t i = 0; i < samples.size(); ++i)
        directions[i] = starts[i] == i ? viewDirection(samples[i].head, settings) : directions[starts[i]];
    return directions;
}

std::vector<Camera> frameSamples(const std::vector<FramingSample>& samples, const std::vector<size_t>& starts,
                                 const Camera& lens, const FramingSettings& settings) {
    const std::vector<Vec3f> directions = viewDirections(samples, starts, settings);
    std::vector<Camera> cameras(samples.size(), lens);
    for (size_t begin = 0, end; begin < samples.size(); begin = end) {
        end = begin + 1;
        while (end < samples.size() && starts[end] == begin) ++end;
        if (settings.follow) {
            for (size_t i = begin; i < end; ++i)
                cameras[i] = fitCamera(lens, directions[i], settings.up, settings.margin, samples[i].spheres);
            continue;
        }
        std::vector<FramingSphere> all;
        for (size_t i = begin; i < end; ++i) all.insert(all.end(), samples[i].spheres.begin(), samples[i].spheres.end());
        const Camera c = fitCamera(lens, directions[begin], settings.up, settings.margin, all);
        std::fill(cameras.begin() + long(begin), cameras.begin() + long(end), c);
    }
    return cameras;
}

}  // namespace hp
