// The dynamic state every strand model keeps the same way: positions and
// velocities at the end of the last step and of the step before (what
// written frames interpolate between), and the root targets of the current
// step (start and end, so a substep finds its root in between). A model's
// own set (sim/guides/guide_group.h GuideSet, sim/curly/curly_state.h
// CurlySet) extends it with its rest shape and inputs.
#pragma once

#include "sim/solver/state_blob.h"
#include "sim/strands/head.h"

#include <Eigen/Geometry>

#include <vector>

namespace hp::strand {

using Mat3f = Eigen::Matrix3f;
using Quatf = Eigen::Quaternionf;

/// @brief The root's orthonormal, right-handed frame as a rotation: columns
/// (tangent, normal, tangent × normal), the normal made unit (+Y when it is
/// zero) and the tangent re-orthogonalised against it (any perpendicular
/// when it is parallel). Rest shapes are stored in these root-local
/// coordinates.
Mat3f rootRotation(const SurfaceFrame& frame);

}  // namespace hp::strand

namespace hp::solver {

/// @brief Positions, velocities and root targets of `count` strands of
/// `vertices` vertices each, structure of arrays: strand g's vertex i is at
/// g·vertices + i.
struct StrandState {
    size_t count = 0;  ///< strands
    int vertices = 0;  ///< vertices per strand (the root included)

    // State at the end of the last step and of the step before.
    std::vector<Vec3f> x, v, xPrev, vPrev;

    // Root targets of the current step: start (= end of the previous step) and end.
    std::vector<Vec3f> rootPos0, rootPos1;
    std::vector<strand::Quatf> rootRot0, rootRot1;

    /// @brief Sizes the arrays for `roots.size()` strands of `vertexCount`
    /// vertices (positions and velocities zero) and puts both root targets on `roots`.
    void resize(const std::vector<SurfaceFrame>& roots, int vertexCount);
    /// @brief The end-of-step root targets from `roots` (same order as
    /// resize); with `start`, the start-of-step targets too.
    void setRoots(const std::vector<SurfaceFrame>& roots, bool start);
    /// @brief The largest distance a root moves over the current step, m.
    float rootJump() const;
    /// @brief Keeps the state as the step before (xPrev, vPrev), at a step's start or after a reset.
    void keepPrevious() {
        xPrev = x;
        vPrev = v;
    }
    /// @brief At a step's end: the end-of-step root targets become the next step's start.
    void advanceRoots();

    /// Root position / rotation at fraction `alpha` of the current step.
    Vec3f rootPosition(size_t g, float alpha) const { return (1.f - alpha) * rootPos0[g] + alpha * rootPos1[g]; }
    strand::Quatf rootRotation(size_t g, float alpha) const { return rootRot0[g].slerp(alpha, rootRot1[g]); }

    /// @brief Appends x, v, xPrev, vPrev and the root targets to a checkpoint.
    void save(BlobWriter& w) const;
    /// @brief Reads what save() wrote into a state sized identically; throws
    /// hp::Error on a size mismatch.
    void restore(BlobReader& r);
};

}  // namespace hp::solver
