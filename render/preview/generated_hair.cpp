#include "render/preview/generated_hair.h"

#include "core/errors.h"

#include <algorithm>
#include <cmath>

namespace hp {

float GeneratedHairSettings::maxLength() const {
    float longest = 0.f;
    for (const HairType& t : types) longest = std::max(longest, float(t.segments) * t.segmentLength);
    return longest;
}

Vec3f hairForce(const GeneratedHairSettings& s, double time, const Vec3f& root) {
    const float windLength = s.wind.norm();
    const float along = windLength > 0.f ? root.dot(s.wind) / windLength : 0.f;
    const float phase = float(2.0 * M_PI) * (s.gustFrequency * float(time) - along / s.gustWavelength);
    return s.gravity + s.wind * (1.f + s.gust * std::sin(phase));
}

std::vector<uint8_t> assignHairTypes(const TriangleMesh& mesh, const GeneratedHairSettings& s,
                                     const Eigen::Isometry3f& toRest, const std::vector<uint8_t>* scalpMask) {
    std::vector<uint8_t> types(mesh.triangleCount(), 0);
    if (!s.enabled || mesh.positions.empty()) return types;
    Eigen::AlignedBox3f restBounds;
    for (const Vec3f& p : mesh.positions) restBounds.extend(toRest * p);
    const Vec3f centre = restBounds.center();
    for (size_t r = 0; r < s.regions.size(); ++r) {
        const HairRegion& region = s.regions[r];
        if (region.type < 0 || size_t(region.type) >= s.types.size() || s.types.size() > 255)
            throw Error(cat("generated hair region ", r, " names hair type ", region.type, " but there are ",
                            s.types.size(), " types"));
        if (region.shape == HairRegion::Shape::Mask && (!scalpMask || scalpMask->size() != mesh.triangleCount()))
            throw Error(cat("generated hair region ", r,
                            " grows on the head's scalp mask, but this head provides no per-triangle mask"));
        const Vec3f axis = region.axis.normalized();
        const float minCos = std::cos(region.angle * float(M_PI) / 180.f);
        for (size_t t = 0; t < mesh.triangleCount(); ++t) {
            bool inside = true;
            if (region.shape == HairRegion::Shape::Mask) {
                inside = (*scalpMask)[t] != 0;
            } else if (region.shape == HairRegion::Shape::Cap) {
                const Tri& tri = mesh.triangles[t];
                const Vec3f c = toRest * ((mesh.positions[tri[0]] + mesh.positions[tri[1]] + mesh.positions[tri[2]]) / 3.f);
                const Vec3f d = c - centre;
                inside = d.squaredNorm() > 0.f && d.normalized().dot(axis) >= minCos;
            }
            if (inside) types[t] = uint8_t(region.type + 1);
        }
    }
    return types;
}

}  // namespace hp
