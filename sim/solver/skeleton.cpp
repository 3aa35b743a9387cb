#include "sim/solver/skeleton.h"

#include "core/errors.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace hp::solver {

Skeleton::Skeleton(StrandModel& model, StrandState& state, std::string name, const StepSettings& settings)
    : model_(model), state_(state), name_(std::move(name)), settings_(settings) {
    if (settings_.threads > 0) arena_ = std::make_shared<tbb::task_arena>(settings_.threads);
}

void Skeleton::start(const HeadPose& head) {
    time_ = prevTime_ = startTime_ = head.time;
    steps_ = 0;
    headTransform_ = head.transform;
    last_ = StepStats{};
    inCut_ = false;
    started_ = true;
}

void Skeleton::requireStarted(const char* what) const {
    if (!started_) throw Error(cat(name_, ": ", what, " before initialize()"));
}

const StepStats& Skeleton::step(const std::vector<SurfaceFrame>& roots, const HeadPose& head) {
    requireStarted("step()");
    if (roots.size() != state_.count)
        throw Error(cat(name_, ": ", roots.size(), " root frames for ", state_.count, " guides"));
    const double expected = nextTime();
    if (std::abs(head.time - expected) > 1e-6 * std::max(1.0, std::abs(expected)))
        throw Error(cat(name_, ": head pose at t = ", head.time, " s, expected the step's end t = ", expected,
                        " s"));
    const auto clock0 = std::chrono::steady_clock::now();
    state_.setRoots(roots, false);
    state_.keepPrevious();

    // A scene cut or teleport: the head or a root jumps further in one step
    // than the limits allow. The strands restart at rest on the new roots.
    // A jump the head file interpolates over several steps is one cut: every
    // step of it restarts the strands on that step's pose (placed outside
    // every collider at their lengths), none of them simulates it as motion
    // (scene_cut.h continuesCut).
    const Eigen::Isometry3f& T0 = headTransform_;
    const Eigen::Isometry3f& T1 = head.transform;
    const StepJump jump = stepJump(T0, T1, state_.rootJump());
    const bool starts = isCut(jump, settings_.teleportDistance, settings_.teleportAngle);
    const bool cut = starts || (inCut_ && continuesCut(jump, settings_.teleportDistance, settings_.teleportAngle));
    model_.beginStep(head, cut);
    if (cut) {
        model_.resetToRest(head);
        state_.keepPrevious();
    } else {
        // The head between its poses at the step's ends: rotation slerped,
        // translation interpolated linearly.
        const strand::Quatf q0(T0.linear()), q1(T1.linear());
        auto headAt = [&](float a) {
            Eigen::Isometry3f t = Eigen::Isometry3f::Identity();
            t.linear() = q0.slerp(a, q1).toRotationMatrix();
            t.translation() = (1.f - a) * T0.translation() + a * T1.translation();
            return t;
        };
        for (int k = 0; k < settings_.substeps; ++k) {
            Substep sub;
            sub.h = settings_.timeStep / float(settings_.substeps);
            sub.alpha = float(k + 1) / float(settings_.substeps);
            sub.headTransform = headAt(sub.alpha);
            const Eigen::Isometry3f prev = headAt(float(k) / float(settings_.substeps));
            // The collider is posed at the step's end (T1): a point at the
            // substep's end maps onto it, and back to where it rode before.
            sub.head.collider = head.collider.get();
            sub.head.toCollider = T1 * sub.headTransform.inverse();
            sub.head.normalToWorld = sub.headTransform.linear() * T1.linear().transpose();
            sub.head.toPrevious = prev * sub.headTransform.inverse();
            model_.substep(sub);
        }
    }
    StepStats counters;
    model_.endStep(cut, counters);
    state_.advanceRoots();
    headTransform_ = head.transform;
    prevTime_ = time_;
    time_ = expected;
    ++steps_;

    last_ = model_.measure(head.collider.get());
    last_.reset = cut;
    last_.cuts = cut && !inCut_ ? 1 : 0;
    inCut_ = cut;
    last_.setCounters(counters);
    last_.msPerStep = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - clock0).count();
    return last_;
}

void Skeleton::write(StrandFrame& frame, double time) const {
    const StrandState& s = state_;
    const double span = time_ - prevTime_;
    if (time < prevTime_ - 1e-9 || time > time_ + 1e-9)
        throw Error(cat(name_, ": cannot write t = ", time, " s; the last step covers [", prevTime_, ", ",
                        time_, "] s"));
    const float a = span > 0 ? float(std::clamp((time - prevTime_) / span, 0.0, 1.0)) : 1.f;
    const int n = s.vertices;
    frame.clear();
    frame.time = time;
    frame.reserve(s.count, size_t(n));
    std::vector<Vec3f> x(n), v(n);
    std::vector<float> r(n);
    for (int i = 0; i < n; ++i)
        r[i] = taperedRadius(settings_.rootRadius, settings_.tipRadius, float(i) / float(n - 1));
    for (size_t g = 0; g < s.count; ++g) {
        for (int i = 0; i < n; ++i) {
            const size_t k = g * size_t(n) + size_t(i);
            x[i] = (1.f - a) * s.xPrev[k] + a * s.x[k];
            v[i] = (1.f - a) * s.vPrev[k] + a * s.v[k];
        }
        // Interpolated chords are shorter than the segments.
        if (a < 1.f) model_.restoreLengths(g, a, x.data());
        frame.addStrand(uint32_t(g), x.data(), r.data(), x.size(), v.data());
    }
    frame.guideCount = uint32_t(s.count);
}

void Skeleton::saveClock(BlobWriter& w) const {
    w.put(time_);
    w.put(prevTime_);
    w.put(startTime_);
    w.put(steps_);
    w.put(headTransform_.matrix());
    w.put(uint8_t(inCut_ ? 1 : 0));
}

void Skeleton::restoreClock(BlobReader& r) {
    time_ = r.get<double>();
    prevTime_ = r.get<double>();
    startTime_ = r.get<double>();
    steps_ = r.get<long>();
    headTransform_.matrix() = r.get<Eigen::Matrix4f>();
    inCut_ = r.get<uint8_t>() != 0;
}

}  // namespace hp::solver
