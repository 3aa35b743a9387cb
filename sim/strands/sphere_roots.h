// @brief Root frames on a sphere head: the roots of the benchmark head
// (SpinningSphere, docs/benchmarks.md) and of the solver tests' sphere heads,
// which hold their roots as head-fixed directions and pose them every step.
// Header-only: only benchmarks and tests use it (the pipeline's roots come
// from sim/strands/roots.h on a mesh).
#pragma once

#include "sim/strands/head.h"

#include <optional>
#include <vector>

namespace hp {

/// @brief Root frames of head-fixed unit directions `dirs` on a sphere of
/// `radius` about the head's origin, carried by `pose` (a root bound to a
/// rigid head moves with it): position pose(radius n), normal R n, tangent
/// R t with t the unit of +Y × n (R: the pose's rotation).
/// @param poleTangent  t for a root at a pole, where +Y × n vanishes; default
///        n.unitOrthogonal() (the guide tests and bench_sim); the curly/wet
///        tests and bench_curly use +X. Either way the pole strand's frame is
///        fixed, so its results are reproducible.
inline std::vector<SurfaceFrame> sphereRootFrames(const std::vector<Vec3f>& dirs, float radius, const HeadPose& pose,
                                                  const std::optional<Vec3f>& poleTangent = std::nullopt) {
    std::vector<SurfaceFrame> roots(dirs.size());
    for (size_t i = 0; i < dirs.size(); ++i) {
        const Vec3f& n = dirs[i];
        Vec3f t = Vec3f::UnitY().cross(n);
        t = t.squaredNorm() > 1e-8f ? Vec3f(t.normalized()) : poleTangent ? *poleTangent : Vec3f(n.unitOrthogonal());
        roots[i].position = pose.transform * (radius * n);
        roots[i].normal = pose.transform.linear() * n;
        roots[i].tangent = pose.transform.linear() * t;
    }
    return roots;
}

}  // namespace hp
