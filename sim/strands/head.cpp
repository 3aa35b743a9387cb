#include "sim/strands/head.h"

#include <cmath>

namespace hp {

void TriangleMesh::computeNormals() {
    normals.assign(positions.size(), Vec3f::Zero());
    for (const Tri& t : triangles) {
        // The unnormalised cross product weights each face by its area.
        const Vec3f n = (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]);
        for (uint32_t i : t) normals[i] += n;
    }
    for (Vec3f& n : normals) {
        const float len = n.norm();
        n = len > 0.f ? Vec3f(n / len) : Vec3f::UnitY();
    }
}

Eigen::AlignedBox3f TriangleMesh::bounds() const {
    Eigen::AlignedBox3f box;
    for (const Vec3f& p : positions) box.extend(p);
    return box;
}

SurfaceFrame evaluate(const TriangleMesh& mesh, const SurfacePoint& point) {
    const Tri& t = mesh.triangles[point.triangle];
    const float b0 = 1.f - point.b1 - point.b2;
    const Vec3f& p0 = mesh.positions[t[0]];
    const Vec3f& p1 = mesh.positions[t[1]];
    const Vec3f& p2 = mesh.positions[t[2]];
    SurfaceFrame f;
    f.position = b0 * p0 + point.b1 * p1 + point.b2 * p2;
    const Vec3f faceNormal = (p1 - p0).cross(p2 - p0).normalized();
    if (mesh.normals.size() == mesh.positions.size()) {
        const Vec3f n = b0 * mesh.normals[t[0]] + point.b1 * mesh.normals[t[1]] + point.b2 * mesh.normals[t[2]];
        f.normal = n.squaredNorm() > 0.f ? Vec3f(n.normalized()) : faceNormal;
    } else {
        f.normal = faceNormal;
    }
    // Gram-Schmidt the first edge against the normal: a tangent that turns
    // with the triangle, so roots carry a frame that rotates with the head.
    Vec3f e = p1 - p0;
    e -= f.normal * f.normal.dot(e);
    if (e.squaredNorm() < 1e-20f) e = f.normal.unitOrthogonal();
    f.tangent = e.normalized();
    return f;
}

float SphereCollider::signedDistance(const Vec3f& p, Vec3f* normal) const {
    const Vec3f d = p - centre_;
    const float len = d.norm();
    if (normal) *normal = len > 0.f ? Vec3f(d / len) : Vec3f::UnitY();
    return len - radius_;
}

TriangleMesh makeSphereMesh(const Vec3f& centre, float radius, int rings, int sectors) {
    TriangleMesh m;
    const float pi = static_cast<float>(M_PI);
    for (int r = 0; r <= rings; ++r) {
        const float theta = pi * r / rings;  // from +Y (north pole) down
        for (int s = 0; s <= sectors; ++s) {
            const float phi = 2.f * pi * s / sectors;
            const Vec3f n(std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi));
            m.positions.push_back(centre + radius * n);
            m.normals.push_back(n);
            m.uvs.emplace_back(float(s) / sectors, 1.f - float(r) / rings);
        }
    }
    const uint32_t stride = sectors + 1;
    for (int r = 0; r < rings; ++r) {
        for (int s = 0; s < sectors; ++s) {
            const uint32_t a = r * stride + s, b = a + stride, c = b + 1, d = a + 1;
            // Counter-clockwise seen from outside; skip the degenerate pole triangles.
            if (r != 0) m.triangles.push_back({a, b, d});
            if (r != rings - 1) m.triangles.push_back({d, b, c});
        }
    }
    return m;
}

SpinningSphere::SpinningSphere(float radius, float degreesPerSecond, int rings, int sectors)
    : radius_(radius), rate_(degreesPerSecond), rest_(makeSphereMesh(Vec3f::Zero(), radius, rings, sectors)) {}

HeadPose SpinningSphere::sample(double time) const {
    HeadPose pose;
    pose.time = time;
    const float angle = static_cast<float>(rate_ * time * M_PI / 180.0);
    pose.transform = Eigen::Isometry3f(Eigen::AngleAxisf(angle, Vec3f::UnitY()));
    pose.mesh = rest_;
    for (Vec3f& p : pose.mesh.positions) p = pose.transform * p;
    for (Vec3f& n : pose.mesh.normals) n = pose.transform.linear() * n;
    pose.collider = std::make_shared<SphereCollider>(Vec3f::Zero(), radius_);
    return pose;
}

}  // namespace hp
