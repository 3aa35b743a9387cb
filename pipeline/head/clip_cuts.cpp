#include "pipeline/head/clip_cuts.h"

#include <algorithm>
#include <cmath>

namespace hp {

std::vector<ClipCut> findClipCuts(const Scene& scene, const HeadSetup& head, double startTime, double endTime,
                                  double step) {
    // Only the mesh and the rigid fit are needed: no collider is built.
    HeadAnimationSettings settings = head.motion->settings();
    settings.collider = ColliderMethod::None;
    AnimatedHead motion(head.rig, settings);
    motion.setFitTriangles(head.scalp);
    std::vector<uint32_t> scalpVertices;
    {
        std::vector<uint8_t> used(head.rest.positions.size(), 0);
        for (size_t t = 0; t < head.scalp.size(); ++t)
            if (head.scalp[t])
                for (uint32_t v : head.rest.triangles[t]) used[v] = 1;
        for (uint32_t v = 0; v < used.size(); ++v)
            if (used[v]) scalpVertices.push_back(v);
    }
    const float maxDistance = float(scene.number("simulation.cut_distance"));
    const float maxAngle = float(scene.number("simulation.cut_angle"));
    auto jumpBetween = [&](const HeadPose& a, const HeadPose& b) {
        float rootMove = 0.f;
        for (uint32_t v : scalpVertices)
            rootMove = std::max(rootMove, (b.mesh.positions[v] - a.mesh.positions[v]).norm());
        return stepJump(a.transform, b.transform, rootMove);
    };
    std::vector<ClipCut> cuts;
    HeadPose previous = motion.sample(startTime);
    HeadPose before;  // the pose before the cut being followed
    bool inCut = false;
    const long steps = std::lround((endTime - startTime) / step);
    for (long k = 1; k <= steps; ++k) {
        HeadPose pose = motion.sample(startTime + double(k) * step);
        const StepJump jump = jumpBetween(previous, pose);
        if (inCut && continuesCut(jump, maxDistance, maxAngle)) {
            ClipCut& c = cuts.back();
            c.time = pose.time;
            ++c.steps;
            c.jump = jumpBetween(before, pose);
        } else if (isCut(jump, maxDistance, maxAngle)) {
            cuts.push_back({pose.time, pose.time, 1, jump});
            before = previous;
            inCut = true;
        } else {
            inCut = false;
        }
        previous = std::move(pose);
    }
    return cuts;
}

}  // namespace hp
