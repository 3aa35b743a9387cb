// Helpers shared by the curly/wet solver tests (test_curly_wet.cpp,
// test_curly_hang.cpp): a moving sphere head, root frames on it, stepping.
#pragma once

#include "sim/curly/curly_wet.h"
#include "sim/strands/head.h"
#include "sim/strands/sphere_roots.h"

#include <functional>
#include <memory>
#include <utility>
#include <vector>

namespace hp::test {

/// A rigid sphere head whose centre follows `path(t)` (no rotation).
class MovingSphere final : public HeadMotion {
  public:
    MovingSphere(float radius, std::function<Vec3f(double)> path) : radius_(radius), path_(std::move(path)) {}
    HeadPose sample(double time) const override {
        HeadPose pose;
        pose.time = time;
        pose.transform = Eigen::Isometry3f(Eigen::Translation3f(path_(time)));
        pose.collider = std::make_shared<SphereCollider>(path_(time), radius_);
        return pose;
    }

  private:
    float radius_;
    std::function<Vec3f(double)> path_;
};

/// Root frames of head-fixed directions on a sphere of `radius`, posed
/// (sim/strands/sphere_roots.h; a root at the pole gets tangent +X, as
/// bench_curly's).
inline std::vector<SurfaceFrame> rootFrames(const std::vector<Vec3f>& dirs, const HeadPose& pose, float radius) {
    return sphereRootFrames(dirs, radius, pose, Vec3f::UnitX());
}

/// Runs `steps` steps of `head`; calls `each` after every step.
inline void simulate(CurlyWetSolver& solver, const HeadMotion& head, const std::vector<Vec3f>& dirs, float radius, int steps,
              const std::function<void(const StepStats&)>& each = {}) {
    const double dt = solver.settings().timeStep;
    for (int k = 0; k < steps; ++k) {
        const HeadPose pose = head.sample(solver.time() + dt);
        const StepStats& s = solver.step(rootFrames(dirs, pose, radius), pose);
        if (each) each(s);
    }
}

inline void start(CurlyWetSolver& solver, const HeadMotion& head, const std::vector<Vec3f>& dirs, float radius,
           const std::vector<std::vector<Vec3f>>* groom = nullptr) {
    const HeadPose pose = head.sample(0.0);
    solver.initialize(rootFrames(dirs, pose, radius), pose, groom);
}

inline std::vector<Vec3f> positions(const CurlyWetSolver& solver) {
    StrandFrame f;
    solver.write(f);
    return f.positions;
}

}  // namespace hp::test
