#include "sim/strands/synthetic_groom.h"

#include "core/errors.h"
#include "sim/strands/fibonacci.h"

#include <algorithm>
#include <cmath>

namespace hp {

SurfaceFrame sphereRootFrame(const Vec3f& direction, float radius) {
    SurfaceFrame f;
    f.normal = direction.normalized();
    f.position = f.normal * radius;
    f.tangent = f.normal.unitOrthogonal();
    return f;
}

FollowerGroom makeSphereGroom(const SphereGroomSettings& s) {
    FollowerGroom g;
    for (const Vec3f& d : fibonacciCap(s.guides, Vec3f::UnitY(), s.capMinCosine))
        g.guideRoots.push_back(sphereRootFrame(d, s.headRadius));
    for (const Vec3f& d : fibonacciCap(s.followers, Vec3f::UnitY(), s.capMinCosine))
        g.followerRoots.push_back(sphereRootFrame(d, s.headRadius));
    g.guideShapes = RestShapes::straight(g.guideRoots.size(), s.vertices, s.length);
    g.followerVertices = {uint32_t(s.vertices)};
    g.followerLengths = {s.length};
    return g;
}

void rotateRoots(const std::vector<SurfaceFrame>& rest, const Eigen::Quaternionf& rotation,
                 std::vector<SurfaceFrame>& out) {
    out.resize(rest.size());
    const Eigen::Matrix3f r = rotation.toRotationMatrix();
    for (size_t i = 0; i < rest.size(); ++i) {
        out[i].position = r * rest[i].position;
        out[i].normal = r * rest[i].normal;
        out[i].tangent = r * rest[i].tangent;
    }
}

SyntheticGuides::SyntheticGuides(const FollowerGroom& groom, const SyntheticGuideSettings& settings)
    : settings_(settings), rest_(groom.guideRoots) {
    for (size_t g = 0; g < rest_.size(); ++g) {
        const uint32_t a = groom.guideShapes.offsets[g], b = groom.guideShapes.offsets[g + 1];
        if (b - a < 2 || b - a > 256) throw Error(cat("synthetic guides: guide ", g, " has ", b - a, " vertices (2 to 256)"));
        vertices_.push_back(b - a);
        float len = 0.f;
        for (uint32_t k = a; k + 1 < b; ++k) len += (groom.guideShapes.points[k + 1] - groom.guideShapes.points[k]).norm();
        lengths_.push_back(len);
    }
}

Eigen::Quaternionf SyntheticGuides::headRotation(double time) const {
    const double angle = settings_.degreesPerSecond * time * M_PI / 180.0;
    return Eigen::Quaternionf(Eigen::AngleAxisf(float(angle), Vec3f::UnitY()));
}

void SyntheticGuides::shape(double time, size_t g, Vec3f* p) const {
    // Head-local shape: sim/strands/synthetic.h's droop toward a target direction that
    // leans sideways (about the strand's own azimuth) with a per-guide phase.
    const Vec3f n = rest_[g].normal;
    const int count = int(vertices_[g]);
    const float segment = lengths_[g] / float(count - 1);
    const float phase = 2.399963f * float(g);  // golden angle: neighbours differ
    const float lean = settings_.sway * float(std::sin(2.0 * M_PI * settings_.swayHz * time + phase));
    Vec3f side = Vec3f::UnitY().cross(n);
    side = side.squaredNorm() > 1e-8f ? Vec3f(side.normalized()) : Vec3f::UnitX();
    const Vec3f target = (Vec3f(0.f, -1.f, 0.f) + lean * side).normalized();
    const Eigen::Matrix3f head = headRotation(time).toRotationMatrix();
    Vec3f x = rest_[g].position;
    p[0] = head * x;
    for (int k = 1; k < count; ++k) {
        const float w = std::min(1.f, settings_.droop * settings_.bend * float(k) / float(count - 1));
        Vec3f d = (1.f - w) * n + w * target;
        if (d.squaredNorm() < 1e-8f) d = n;
        x += segment * d.normalized();
        const float dist = x.norm();
        const float minDist = settings_.headRadius * 1.0005f;
        if (dist < minDist) x *= minDist / dist;  // slide over the head, as sim/strands/synthetic.h
        p[k] = head * x;
    }
}

void SyntheticGuides::sample(double time, StrandFrame& guides, std::vector<SurfaceFrame>& guideRoots) const {
    const size_t G = rest_.size();
    guides.frame = 0;
    guides.time = time;
    guides.guideCount = uint32_t(G);
    guides.offsets.resize(G + 1);
    guides.offsets[0] = 0;
    for (size_t g = 0; g < G; ++g) guides.offsets[g + 1] = guides.offsets[g] + vertices_[g];
    const size_t total = guides.offsets[G];
    guides.positions.resize(total);
    guides.velocities.resize(total);
    guides.radii.resize(total);
    guides.ids.resize(G);
    constexpr double h = 1e-3;
    Vec3f before[256];
    for (size_t g = 0; g < G; ++g) {
        Vec3f* p = guides.positions.data() + guides.offsets[g];
        shape(time, g, p);
        shape(time - h, g, before);
        for (uint32_t k = 0; k < vertices_[g]; ++k) {
            guides.velocities[guides.offsets[g] + k] = (p[k] - before[k]) / float(h);
            guides.radii[guides.offsets[g] + k] = taperedRadius(0.00004f, 0.00001f, float(k) / float(vertices_[g] - 1));
        }
        guides.ids[g] = uint32_t(g);
    }
    rotateRoots(rest_, headRotation(time), guideRoots);
}

}  // namespace hp
