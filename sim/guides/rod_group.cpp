// The `rod` formulation (the default): each guide is an inextensible elastic
// rod, advanced by sim/guides/rod_kernels.h's XPBD step with a direct banded solve.
// No Bullet world: a rod group is a slice of guides and their rest
// curvatures; strand-strand contacts (Bullet's broadphase and narrowphase,
// sim/guides/strand_contacts.cpp) act on the shared state between substeps as for
// the rope.
//
// Parameters (GuideSettings → rod::Material): mass per length μ and bending
// stiffness EI from E, ρ, the fibre radius and hairs_per_guide, which
// cancels out of the motion (μ and EI are both N times one hair's). The
// fibre is the one drawn: its radius tapers from hair.radius.root to
// hair.radius.tip (rod::Material), so EI_j is taken per joint and the
// masses per segment. The
// shear modulus is not read: with an isotropic section (EI the same about
// both axes) and a free tip, the quasistatic twist moment is zero along the
// rod (Bergou et al., "Discrete Elastic Rods", 2008, §4.2: the material
// frame relaxes to the twist-free Bishop frame), so the material frame is
// the transported frame and the bending energy alone drives the dynamics.
// That is the model's twist assumption; anisotropic (elliptic) fibres would
// need twist, and GJ with it (the curly model uses it: sim/curly/).
//
// Why this solver (measured on the 2-core machine, loaded; README "Physics
// of the guides"): the direct banded solve is exact per linearisation, so
// the static elastica comes out within 0.3% of L at 0.01 s steps; one XPBD
// step per 0.02 s is unstable (a hanging chain's tip oscillation grows), two
// are the default; a 23-segment strand costs ~4.6 µs of CPU per XPBD step
// with four strands per SIMD batch (B-sim, 845 guides, loaded machine;
// sim/guides/rod_step.cpp), about 1.1× the rope's step.
// Gauss-Seidel XPBD (cheaper per sweep, softer than its EI when
// under-converged) was not measured.
#include "sim/guides/guide_group.h"
#include "sim/guides/rod_kernels.h"
#include "sim/guides/rod_preload.h"

#include <algorithm>
#include <utility>

namespace hp::guides {
namespace {

rod::Material materialOf(const GuideSettings& s) {
    rod::Material m;
    m.youngs = s.youngsModulus;
    m.density = s.density;
    m.radius = s.rootRadius;
    m.tipRadius = s.taperedFibre ? s.tipRadius : s.rootRadius;
    m.hairsPerGuide = s.hairsPerGuide;
    return m;
}

class RodGroup final : public GuideGroup {
  public:
    RodGroup(GuideSet& set, size_t begin, size_t end)
        : GuideGroup(set, begin, end), bendStiffness_(materialOf(set.settings).bendStiffness()) {
        const size_t n = end - begin;
        invMass_.resize(n * size_t(set.vertices));
        curvature_.resize(n * size_t(set.segments));
        for (size_t k = 0; k < invMass_.size(); ++k) {
            const float m = set.mass[set.vertex(begin, 0) + k];
            invMass_[k] = m > 0.f ? 1.f / m : 0.f;
        }
        // EI_j of the tapered fibre at joint j's vertex (arc-length fraction
        // of the rest lengths); the masses taper alike (GuideSolver::initialize).
        const rod::Material material = materialOf(set.settings);
        jointStiffness_.resize(n * size_t(set.segments));
        for (size_t g = begin; g < end; ++g) {
            double length = 0, arc = 0;
            for (int j = 0; j < set.segments; ++j) length += set.restLength[set.segment(g, j)];
            for (int j = 0; j < set.segments; ++j) {
                jointStiffness_[(g - begin) * size_t(set.segments) + size_t(j)] = material.bendStiffnessAt(arc / length);
                arc += set.restLength[set.segment(g, j)];
            }
        }
        for (size_t g = begin; g < end; ++g) computeCurvature(g, 0.f);
        if (bdf2()) {
            xBack_.assign(invMass_.size(), Vec3f::Zero());  // defined bytes for a checkpoint before the first step
            vBack_.assign(invMass_.size(), Vec3f::Zero());
        }
    }

    void reset() override {
        GuideGroup::reset();
        restart_ = true;  // after the solver has placed the reset guides outside the head
    }
    void save(BlobWriter& w) const override {
        w.put(restart_);
        w.array(xBack_);
        w.array(vBack_);
    }
    void restore(BlobReader& r) override {
        restart_ = r.get<bool>();
        r.array(xBack_, xBack_.size());
        r.array(vBack_, vBack_.size());
    }
    void preload(const SubstepContext& ctx) override {
        // From rest a BDF2 step is the implicit Euler step of h' (rod::bdf2Step).
        float h = ctx.h / float(std::max(1, set_.settings.rodSubsteps));
        if (bdf2()) h = rod::bdf2Step(h);
        // The head at the first frame, where the groom may lean on it
        // (ctx.head: the collider posed there; headCollision is off during
        // the pre-load so that no other formulation projects).
        const GuideSettings& s = set_.settings;
        rod::PreloadContact contact;
        if (s.preloadContact && s.headCollision && ctx.head.collider) contact.head = &ctx.head;
        contact.radius = s.collisionRadius;
        contact.reach = s.preloadReach;
        for (size_t g = begin_; g < end_; ++g) computeCurvature(g, s.preload ? h : 0.f, contact);
    }
    void substep(const SubstepContext& ctx) override;
    void displaced(const Vec3f* before) override {
        if (!bdf2() || restart_) return;
        const size_t first = set_.vertex(begin_, 0);
        for (size_t k = 0; k < xBack_.size(); ++k) xBack_[k] += set_.x[first + k] - before[first + k];
    }
    size_t takePinned() override { return std::exchange(pinned_, size_t(0)); }

  private:
    bool bdf2() const { return set_.settings.rodIntegrator == RodIntegrator::Bdf2; }
    /// BDF2's history for the group's guides as they are now, as if they had
    /// moved at their present velocities (rod::bdf2Start).
    void restartHistory() {
        restart_ = false;
        if (!bdf2()) return;
        const float h = historyStep();
        const size_t first = set_.vertex(begin_, 0);
        rod::bdf2Start(&set_.x[first], &set_.v[first], int(xBack_.size()), h, xBack_.data(), vBack_.data());
    }
    /// The rod's own step, s.
    float historyStep() const {
        return set_.settings.timeStep / float(std::max(1, set_.settings.substeps)) /
               float(std::max(1, set_.settings.rodSubsteps));
    }
    rod::RodStrand strand(size_t g) const {
        rod::RodStrand s;
        s.vertices = set_.vertices;
        s.restLength = &set_.restLength[set_.segment(g, 0)];
        s.invMass = &invMass_[(g - begin_) * size_t(set_.vertices)];
        s.restCurvature = &curvature_[(g - begin_) * size_t(set_.segments)];
        s.ghostDir = set_.groomDir[set_.segment(g, 0)];
        s.bendStiffness = bendStiffness_;
        s.jointStiffness = &jointStiffness_[(g - begin_) * size_t(set_.segments)];
        return s;
    }
    /// Rest curvatures of guide g from its rest shape at the end-of-step
    /// root; with a pre-load step h > 0, the rest shape is made a static
    /// equilibrium of steps of h under gravity and the head's contact (rod::preload).
    void computeCurvature(size_t g, float preloadStep, const rod::PreloadContact& contact = {}) {
        const Mat3f R = set_.rootRot1[g].toRotationMatrix();
        std::vector<Vec3f> x(size_t(set_.vertices));
        set_.restShape(g, set_.rootPos1[g], R, x.data());
        const rod::RodStrand s = strand(g);
        rod::Vec2f* c = &curvature_[(g - begin_) * size_t(set_.segments)];
        rod::restCurvature(s, x.data(), R, c);
        if (preloadStep > 0.f)
            rod::preload(s, x.data(), R, set_.settings.gravity, preloadStep, set_.settings.preloadProbes, contact,
                         set_.settings.preloadLimit, c,
                         scratch_);
    }

    const double bendStiffness_;  ///< EI at the root (> 0: the guides bend)
    std::vector<double> jointStiffness_;  ///< EI_j per joint of each guide (the taper)
    std::vector<float> invMass_;
    std::vector<rod::Vec2f> curvature_;
    std::vector<Vec3f> xBack_, vBack_;  ///< BDF2's history x_{n-1}, v_{n-1} per vertex (empty for Euler)
    bool restart_ = true;               ///< the history starts afresh at the next substep (a start, a reset)
    rod::RodScratch scratch_;
    size_t pinned_ = 0;
};

void RodGroup::substep(const SubstepContext& ctx) {
    const GuideSettings& s = set_.settings;
    const strand::HeadQuery* head = ctx.collidingHead();
    // The rod's own steps inside the solver's substep: root targets
    // interpolated over [alpha0, alpha].
    const int k = std::max(1, s.rodSubsteps);
    const float h = ctx.h / float(k);
    const float alpha0 = ctx.alpha - ctx.h / s.timeStep;
    if (restart_) restartHistory();
    // Guides in batches of rod::kLanes (their banded solves share SIMD
    // lanes; each guide's result is that of a lone step).
    for (size_t g0 = begin_; g0 < end_; g0 += rod::kLanes) {
        const int count = int(std::min<size_t>(rod::kLanes, end_ - g0));
        rod::RodStrand strands[rod::kLanes];
        rod::RodStepTarget targets[rod::kLanes];
        for (int l = 0; l < count; ++l) {
            const size_t g = g0 + size_t(l);
            strands[l] = strand(g);
            targets[l].strand = &strands[l];
            targets[l].x = &set_.x[set_.vertex(g, 0)];
            targets[l].v = &set_.v[set_.vertex(g, 0)];
            targets[l].ignoreParts = set_.ignoredParts(g);
            if (bdf2()) {
                targets[l].xBack = &xBack_[(g - begin_) * size_t(set_.vertices)];
                targets[l].vBack = &vBack_[(g - begin_) * size_t(set_.vertices)];
            }
        }
        for (int i = 0; i < k; ++i) {
            const float a = alpha0 + (ctx.alpha - alpha0) * float(i + 1) / float(k);
            for (int l = 0; l < count; ++l) {
                targets[l].rootPos = set_.rootPosition(g0 + size_t(l), a);
                targets[l].rootFrame = set_.rootRotation(g0 + size_t(l), a).toRotationMatrix();
            }
            pinned_ += size_t(rod::rodSteps(targets, count, s.gravity, h, s.damping, s.friction, head,
                                            s.collisionRadius, scratch_));
        }
    }
}

class RodFormulation final : public Formulation {
  public:
    std::unique_ptr<GuideGroup> makeGroup(GuideSet& set, size_t begin, size_t end) override {
        return std::make_unique<RodGroup>(set, begin, end);
    }
};

}  // namespace

std::unique_ptr<Formulation> makeRodFormulation() { return std::make_unique<RodFormulation>(); }

double rodMassPerLength(const GuideSettings& s) {
    const rod::Material m = materialOf(s);
    return s.taperedFibre ? m.meanMassPerLength() : m.massPerLength();  // the latter: the uniform fibre's bits
}

double rodSegmentMass(const GuideSettings& s, double t0, double t1, double length) {
    return materialOf(s).segmentMass(t0, t1, length);
}

}  // namespace hp::guides
