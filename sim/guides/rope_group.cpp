// The production formulation: each guide is a Bullet soft-body rope; the
// ropes of a group are the disconnected chains of one btSoftBody (a bundle,
// see Bundle below) in the group's own btSoftRigidDynamicsWorld, with the
// kernels of sim/guides/joint_kernels.h at Bullet's solver extension point and
// after its step.
//
// One Bullet step h:
//  1. Bullet predictMotion: integrates gravity and velocities. The root node
//     has zero mass and moves by velocity to its kinematic target, so head
//     motion enters the strand as real velocity.
//  2. StrandSoftBodySolver (Bullet's default soft-body solver with one
//     override): compressed segments are relieved root to tip, the Drive
//     pass turns each joint toward its (gravity pre-loaded) rest direction —
//     an implicit joint drive, carried to the subtree — then Bullet's own
//     link kernel (btSoftBody::PSolve_Links, `iterations` mass-weighted
//     Gauss-Seidel passes) runs interleaved with the bend limits expressed as
//     spans between every other vertex, so both sides of a joint stop move
//     and tension carries reactions along the chain.
//  3. Finish pass: exact segment lengths (follow-the-leader), the projection
//     limit, projection out of the head's signed distance keeping the
//     collision radius clear; velocities from positions, Coulomb friction
//     against the moving head, damping exp(-c·h).
//
// Why this arrangement (B-sim measurements on this 2-core machine are in the
// report and in tools/bench/bench_sim.cpp's output):
//  - Probes of Bullet's chain primitives on this project's 2-core machine
//    (23 links, 0.25 m, 0.1 m sphere head at 90°/s, 0.02 s steps):
//    btMultiBody keeps lengths exact, but joint springs applied as explicit
//    torques are stable at 0.02 s only ~70× softer than what holds a strand
//    against gravity (the outer links' inertia is tiny), and it costs ~2 ms
//    per step for 94 chains before any spring; rigid
//    6-DoF chains tear at one step (reproduced here: a plain 23-link chain
//    hung 0.6 m below its 0.25 m length, limits broken); soft-body ropes
//    stretch ~12% at one step. Ropes are the cheapest Bullet primitive, and
//    a follow-the-leader pass after the step makes lengths exact (measured:
//    |l/l0 - 1| ≤ 2e-6) at one Bullet step per 0.02 s instead of 4–8 substeps.
//  - Springs applied after Bullet's step fought the limp chain's response:
//    under compression Gauss-Seidel folds a chain (8° zig-zags at the root of
//    a standing strand), hence the compression relief; springs correcting
//    Bullet's result left a 20° root kink per step that no pre-load could
//    reach, hence springs on the prediction, before the link solve.
//  - Limits corrected on one vertex ratchet the excess down the chain (limp
//    strands curled at ±30° on every joint); carried rigidly, they held limp
//    strands out like sticks. As spans inside the link iterations they hang
//    correctly (30°, 30°, 30° then straight down from a horizontal root).
//  - Head contact by projection out of the signed distance, not Bullet's
//    soft-rigid collision: a deforming head needs no Bullet shape, fast
//    strands cannot tunnel (measured: no vertex inside the head at 720°/s),
//    and it costs one distance query per vertex.
//  - Worlds whose ropes never pair in the broadphase (collision mask 0) cost
//    linear time per guide and run in parallel; contact pools are shrunk
//    (Bullet preallocates ~4 MB per world by default).
//  - One body per group rather than one per rope (B-sim, 845 guides, one
//    thread: 14.3 -> 8.3 CPU ms per step, identical results): Bullet's link
//    kernel overlaps the ropes' dependency chains, and its per-body work
//    (bounds, node tree, solver preparation) is paid once per group. The
//    Drive pass runs four ropes at a time, in lockstep (9.7 -> 7.9 CPU ms
//    per step, min of five alternating runs each on a loaded machine) and
//    then in SIMD lanes (strand::driveJoints; 8.2 -> 6.8): identical results.
#include "sim/collision/bullet_adapter.h"
#include "sim/guides/guide_group.h"

#include <cmath>
#include <memory>

namespace hp::guides {
namespace {

using bullet::bt;
using bullet::ei;

/// The ropes of one group are one btSoftBody, a bundle of disconnected
/// chains: node i of rope b is m_nodes[i·B + b] and link j of rope b is
/// m_links[j·B + b]. Bullet's link kernel (PSolve_Links) is Gauss-Seidel in
/// link order, so each rope sees exactly the same updates in the same order
/// as a body of its own, but consecutive links now belong to different ropes:
/// the chain of dependent updates along one rope (each link, a division
/// among its operations, waits for its parent's result) overlaps with the
/// other ropes' chains instead of stalling the core. Bullet's per-body work
/// (bounds, trees, solver preparation) is paid once per group, not per rope.
class Bundle {
  public:
    Bundle(btSoftBody* body, size_t ropes) : body_(body), ropes_(int(ropes)) {}
    btSoftBody::Node& node(size_t rope, int i) const { return body_->m_nodes[i * ropes_ + int(rope)]; }
    btSoftBody* body() const { return body_; }
    int ropes() const { return ropes_; }

  private:
    btSoftBody* body_;
    int ropes_;
};

/// Bullet's default soft-body solver with the joint kernels at its
/// extension point: after predictMotion has integrated gravity and before
/// the link solve, each rope's compressed segments are relieved and the
/// Drive pass (springs, soft limits) turns its joints; Bullet's two-sided
/// link solve then carries their reactions along the chain.
/// Bend limits are checked after every 4th link iteration: a quarter of the
/// cost, the same steady state (the limit fraction is spread over the checks).
constexpr int kLimitStride = 4;

class StrandSoftBodySolver final : public btDefaultSoftBodySolver {
  public:
    /// Solves guides [begin, end) of `set`: squares their spans (only theirs:
    /// every group has its own solver).
    StrandSoftBodySolver(GuideSet& set, size_t begin, size_t end) : set_(set), begin_(begin) {
        for (size_t k = set.segment(begin, 0); k < set.segment(end, 0); ++k) {
            minSpan2_.push_back(set.minSpan[k] * set.minSpan[k]);
            maxSpan2_.push_back(set.maxSpan[k] * set.maxSpan[k]);
        }
    }
    void setBundle(const Bundle& bundle) { bundle_ = bundle; }
    /// What the next solveConstraints does: the pass and the step's context.
    void prepare(strand::JointPass pass, const SubstepContext& ctx) {
        pass_ = pass;
        ctx_ = &ctx;
    }
    void solveConstraints(btScalar solverdt) override {
        const int iterations = set_.settings.iterations;
        const int n = set_.vertices, ropes = bundle_.ropes();
        x_.resize(size_t(n * ropes));
        xs_.resize(size_t(ropes));
        frames_.resize(size_t(ropes));
        joints_.resize(size_t(ropes));
        follicle_.resize(ropes);
        // Rope b's vertices at x_[b·n ...], read in the bundle's node order.
        for (int i = 0; i < n; ++i)
            for (int b = 0; b < ropes; ++b) x_[size_t(b * n + i)] = ei(bundle_.node(b, i).m_x);
        for (int b = 0; b < ropes; ++b) {
            const size_t g = begin_ + size_t(b);
            xs_[b] = &x_[size_t(b * n)];
            strand::relieveCompression(xs_[b], &set_.restLength[set_.segment(g, 0)], size_t(n));
            frames_[b] = set_.rootRotation(g, ctx_->alpha).toRotationMatrix();
            joints_[b] = set_.joints(g);
            const size_t s0 = set_.segment(g, 0);
            follicle_[b] = bt(Vec3f(xs_[b][0] - frames_[b] * (set_.restLength[s0] * set_.groomDir[s0])));
        }
        if (pass_ == strand::JointPass::Drive)
            strand::driveJoints(ropes, xs_.data(), n, frames_.data(), joints_.data());
        else
            for (int b = 0; b < ropes; ++b)
                strand::relaxJoints(pass_, xs_[b], n, frames_[b], joints_[b], nullptr, 0.f, nullptr);
        for (int i = 1; i < n; ++i)
            for (int b = 0; b < ropes; ++b) bundle_.node(b, i).m_x = bt(x_[size_t(b * n + i)]);
        // Bullet's link solve (its own Gauss-Seidel kernel, all ropes of the
        // bundle interleaved), with the bend limits as spans so both sides
        // of a stop move.
        btSoftBody* body = bundle_.body();
        for (int it = 0; it < iterations; ++it) {
            btSoftBody::PSolve_Links(body, 1, btScalar(it) / btScalar(iterations));
            // The limits every kLimitStride-th link iteration and after the last.
            if ((it + 1) % kLimitStride != 0 && it + 1 != iterations) continue;
            for (int b = 0; b < ropes; ++b) limits(b);
        }
        // Bullet's own pass: its position loop is off (piterations = 0), the
        // rest (link and anchor preparation) runs as usual.
        btDefaultSoftBodySolver::solveConstraints(solverdt);
    }

  private:
    void limits(int b) {
        const size_t s0 = set_.segment(begin_ + size_t(b), 0);
        const size_t own0 = size_t(b) * size_t(set_.segments);  // rope b's first span in minSpan2_ / maxSpan2_
        for (int j = 0; j < set_.segments; ++j) {
            btSoftBody::Node& child = bundle_.node(b, j + 1);
            const btVector3& from = j == 0 ? follicle_[b] : bundle_.node(b, j - 1).m_x;
            // Most joints are inside their limits: test squared spans first.
            const btScalar d2 = (child.m_x - from).length2();
            if (d2 >= minSpan2_[own0 + j] && d2 <= maxSpan2_[own0 + j]) continue;
            Vec3f a = ei(from), b1 = ei(child.m_x);
            const float wa = j == 0 ? 0.f : bundle_.node(b, j - 1).m_im;
            strand::limitSpan(a, b1, wa, child.m_im, set_.minSpan[s0 + j], set_.maxSpan[s0 + j],
                              set_.limitPerIteration[s0 + j]);
            if (j > 0) bundle_.node(b, j - 1).m_x = bt(a);
            child.m_x = bt(b1);
        }
    }

    GuideSet& set_;
    size_t begin_;
    Bundle bundle_{nullptr, 0};
    strand::JointPass pass_ = strand::JointPass::Drive;
    const SubstepContext* ctx_ = nullptr;
    // Scratch: every rope's vertices, and per rope its root frame and joints.
    std::vector<Vec3f> x_;
    std::vector<Vec3f*> xs_;
    std::vector<Mat3f> frames_;
    std::vector<strand::JointParams> joints_;
    btAlignedObjectArray<btVector3> follicle_;
    std::vector<btScalar> minSpan2_, maxSpan2_;  ///< squared spans of the group's guides, per segment
};

class RopeGroup final : public GuideGroup {
  public:
    RopeGroup(GuideSet& set, size_t begin, size_t end);
    ~RopeGroup() override;

    void preload(const SubstepContext& ctx) override;
    void substep(const SubstepContext& ctx) override;

  private:
    void load(size_t g, float h, float alpha);
    void loadAll(float h, float alpha);
    void relax(size_t g, const SubstepContext& ctx);

    StrandSoftBodySolver softSolver_{set_, begin_, end_};
    // Ropes never touch anything in their world, so its contact pools stay tiny.
    bullet::RopeWorld world_{set_.settings.gravity, &softSolver_, bullet::smallPools()};
    std::unique_ptr<btSoftBody> body_;
    Bundle bundle_{nullptr, 0};
    // Scratch for one guide, reused (groups run one at a time per thread).
    std::vector<Vec3f> x_;
    std::vector<strand::Contact> contact_;
    unsigned loadedVersion_ = ~0u;  ///< set_.version the nodes were last synchronised with
};

RopeGroup::RopeGroup(GuideSet& set, size_t begin, size_t end) : GuideGroup(set, begin, end) {
    const int n = set.vertices;
    const int ropes = int(end - begin);
    x_.resize(n);
    contact_.resize(n);
    std::vector<btVector3> pos(size_t(n * ropes));
    std::vector<btScalar> mass(size_t(n * ropes));
    for (int b = 0; b < ropes; ++b)
        for (int i = 0; i < n; ++i) {
            const size_t k = set.vertex(begin + size_t(b), i);
            pos[size_t(i * ropes + b)] = bt(set.x[k]);
            mass[size_t(i * ropes + b)] = set.mass[k];  // root: 0 = kinematic
        }
    body_ = std::make_unique<btSoftBody>(&world_.info(), n * ropes, pos.data(), mass.data());
    btSoftBody* body = body_.get();
    bundle_ = Bundle(body, size_t(ropes));
    // Links segment-major: consecutive links belong to different ropes.
    for (int j = 0; j < set.segments; ++j)
        for (int b = 0; b < ropes; ++b) body->appendLink(j * ropes + b, (j + 1) * ropes + b);
    // Bullet keeps a tree of node boxes per body, checked every step (no
    // collision uses it here). Its margin m pads each box by m and lets a node
    // move m/4 before its box is re-inserted: with 2 m that almost never
    // happens, where 5 cm re-inserted boxes of fast tips every few steps.
    body->getCollisionShape()->setMargin(2.f);
    // The link iterations run in StrandSoftBodySolver, with the limits
    // (Bullet's own position loop is off); damping is the kernels' exp(-c·h);
    // head contact is the signed-distance projection.
    world_.addRope(body, 0);
    softSolver_.setBundle(bundle_);
}

RopeGroup::~RopeGroup() { world_.removeRope(body_.get()); }

void RopeGroup::load(size_t g, float h, float alpha) {
    const size_t b = g - begin_;
    // The nodes already hold the state relax() stored, unless something else
    // (a reset, strand-strand contacts) wrote the shared arrays since.
    if (loadedVersion_ != set_.version) {
        for (int i = 0; i < set_.vertices; ++i) {
            btSoftBody::Node& node = bundle_.node(b, i);
            node.m_x = bt(set_.x[set_.vertex(g, i)]);
            node.m_v = bt(set_.v[set_.vertex(g, i)]);
        }
    }
    // The massless root moves to its target by velocity during
    // predictMotion, so head motion enters the strand as real velocity.
    bundle_.node(b, 0).m_v = bt((set_.rootPosition(g, alpha) - set_.x[set_.vertex(g, 0)]) / h);
}

void RopeGroup::loadAll(float h, float alpha) {
    for (size_t g = begin_; g < end_; ++g) load(g, h, alpha);
    loadedVersion_ = set_.version;
}

void RopeGroup::preload(const SubstepContext& ctx) {
    // One Bullet step from rest with the pre-load pass in place of Drive:
    // it sees exactly the prediction Drive will see at rest and aims each
    // spring so that Drive lands on the rest shape, an exact equilibrium.
    // The targets are joint angles, like a pre-bent rod's, so they turn with
    // the parent segment; a push fixed in space instead (a follower load on
    // a cantilever) flutters (measured: ×4 energy per step).
    loadedVersion_ = ~set_.version;  // force a full load
    loadAll(ctx.h, ctx.alpha);
    softSolver_.prepare(strand::JointPass::SolvePreload, ctx);
    world_.step(ctx.h);
    loadedVersion_ = ~set_.version;  // the nodes hold the probe step, not the state
}

void RopeGroup::substep(const SubstepContext& ctx) {
    loadAll(ctx.h, ctx.alpha);
    softSolver_.prepare(strand::JointPass::Drive, ctx);
    world_.step(ctx.h);
    for (size_t g = begin_; g < end_; ++g) relax(g, ctx);
}

void RopeGroup::relax(size_t g, const SubstepContext& ctx) {
    const GuideSettings& s = set_.settings;
    const float h = ctx.h;
    const strand::HeadQuery* head = ctx.collidingHead();
    const size_t b = g - begin_;
    const int n = set_.vertices;
    for (int i = 0; i < n; ++i) x_[i] = ei(bundle_.node(b, i).m_x);
    x_[0] = set_.rootPosition(g, ctx.alpha);
    strand::relaxJoints(strand::JointPass::Finish, x_.data(), n, set_.rootRotation(g, ctx.alpha).toRotationMatrix(),
                        set_.joints(g), head, s.collisionRadius, contact_.data());

    // Velocities from positions (position-based dynamics), then friction
    // against the moving head and step-size independent damping.
    const float damp = strand::dampingFactor(s.damping, h);
    for (int i = 0; i < n; ++i) {
        const size_t k = set_.vertex(g, i);
        Vec3f v = strand::stepVelocity(set_.x[k], x_[i], h, contact_[i], ctx.head, s.friction);
        if (i > 0) v *= damp;
        set_.x[k] = x_[i];
        set_.v[k] = v;
        btSoftBody::Node& node = bundle_.node(b, i);
        node.m_x = bt(x_[i]);
        node.m_v = bt(v);
    }
}

class RopeFormulation final : public Formulation {
  public:
    std::unique_ptr<GuideGroup> makeGroup(GuideSet& set, size_t begin, size_t end) override {
        return std::make_unique<RopeGroup>(set, begin, end);
    }
};

}  // namespace

std::unique_ptr<Formulation> makeRopeFormulation(const GuideSet&) { return std::make_unique<RopeFormulation>(); }

}  // namespace hp::guides
