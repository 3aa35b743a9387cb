// The production formulation: each guide is a Bullet soft-body rope
// (btSoftBody in a btSoftRigidDynamicsWorld, one world per group of guides),
// with the kernels of sim/strand_constraints.h at Bullet's solver extension
// point and after its step.
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
//  - STACK.md's probes: btMultiBody exact but its explicit springs far too
//    soft at 0.02 s, and ~2 ms/step for 94 chains before any spring; rigid
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
#include "sim/guide_group.h"

#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <cmath>

namespace hp::guides {
namespace {

inline btVector3 bt(const Vec3f& v) { return btVector3(v.x(), v.y(), v.z()); }
inline Vec3f ei(const btVector3& v) { return Vec3f(v.x(), v.y(), v.z()); }

/// Ropes never touch anything in their world, so its contact pools stay
/// tiny (Bullet's default preallocates ~4 MB per world).
btDefaultCollisionConstructionInfo smallPools() {
    btDefaultCollisionConstructionInfo info;
    info.m_defaultMaxPersistentManifoldPoolSize = 16;
    info.m_defaultMaxCollisionAlgorithmPoolSize = 16;
    return info;
}

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
    explicit StrandSoftBodySolver(GuideSet& set) : set_(set) {
        for (size_t k = 0; k < set.minSpan.size(); ++k) {
            minSpan2_.push_back(set.minSpan[k] * set.minSpan[k]);
            maxSpan2_.push_back(set.maxSpan[k] * set.maxSpan[k]);
        }
    }
    /// What the next solveConstraints does: the pass and the step's context.
    void prepare(strand::JointPass pass, const SubstepContext& ctx) {
        pass_ = pass;
        ctx_ = &ctx;
    }
    void solveConstraints(btScalar solverdt) override {
        const int iterations = set_.settings.iterations;
        for (int b = 0; b < m_softBodySet.size(); ++b) {
            btSoftBody* body = m_softBodySet[b];
            const size_t g = size_t(body->getUserIndex());
            const int n = body->m_nodes.size();
            x_.resize(n);
            for (int i = 0; i < n; ++i) x_[i] = ei(body->m_nodes[i].m_x);
            strand::relieveCompression(x_.data(), &set_.restLength[set_.segment(g, 0)], size_t(n));
            const Mat3f R = set_.rootRotation(g, ctx_->alpha).toRotationMatrix();
            strand::relaxJoints(pass_, x_.data(), n, R, set_.joints(g), nullptr, 0.f, nullptr);
            for (int i = 1; i < n; ++i) body->m_nodes[i].m_x = bt(x_[i]);
            // Bullet's link solve (its own Gauss-Seidel kernel), interleaved
            // with the bend limits as spans so both sides of a stop move.
            const size_t s0 = set_.segment(g, 0);
            const btVector3 follicleBt = bt(Vec3f(x_[0] - R * (set_.restLength[s0] * set_.groomDir[s0])));
            for (int it = 0; it < iterations; ++it) {
                btSoftBody::PSolve_Links(body, 1, btScalar(it) / btScalar(iterations));
                // The limits every kLimitStride-th link iteration and after the last.
                if ((it + 1) % kLimitStride != 0 && it + 1 != iterations) continue;
                for (int j = 0; j < set_.segments; ++j) {
                    btSoftBody::Node& child = body->m_nodes[j + 1];
                    const btVector3& from = j == 0 ? follicleBt : body->m_nodes[j - 1].m_x;
                    // Most joints are inside their limits: test squared spans first.
                    const btScalar d2 = (child.m_x - from).length2();
                    if (d2 >= minSpan2_[s0 + j] && d2 <= maxSpan2_[s0 + j]) continue;
                    Vec3f a = ei(from), b1 = ei(child.m_x);
                    const float wa = j == 0 ? 0.f : body->m_nodes[j - 1].m_im;
                    strand::limitSpan(a, b1, wa, child.m_im, set_.minSpan[s0 + j], set_.maxSpan[s0 + j],
                                      set_.limitPerIteration[s0 + j]);
                    if (j > 0) body->m_nodes[j - 1].m_x = bt(a);
                    child.m_x = bt(b1);
                }
            }
        }
        // Bullet's own pass: its position loop is off (piterations = 0), the
        // rest (link and anchor preparation) runs as usual.
        btDefaultSoftBodySolver::solveConstraints(solverdt);
    }

  private:
    GuideSet& set_;
    strand::JointPass pass_ = strand::JointPass::Drive;
    const SubstepContext* ctx_ = nullptr;
    std::vector<Vec3f> x_;
    std::vector<btScalar> minSpan2_, maxSpan2_;
};

class RopeGroup final : public GuideGroup {
  public:
    RopeGroup(GuideSet& set, size_t begin, size_t end);
    ~RopeGroup() override;

    void reset() override;
    void preload(const SubstepContext& ctx) override;
    void substep(const SubstepContext& ctx) override;
    double kineticEnergy() const override;
    void jointAngles(float& bend, float& twist) const override;

  private:
    void load(size_t g, float h, float alpha);
    void loadAll(float h, float alpha);
    void relax(size_t g, const SubstepContext& ctx);

    btSoftBodyRigidBodyCollisionConfiguration config_{smallPools()};
    btCollisionDispatcher dispatcher_{&config_};
    btDbvtBroadphase broadphase_;
    btSequentialImpulseConstraintSolver solver_;
    StrandSoftBodySolver softSolver_{set_};
    btSoftRigidDynamicsWorld world_{&dispatcher_, &broadphase_, &solver_, &config_, &softSolver_};
    std::vector<btSoftBody*> bodies_;
    // Scratch for one guide, reused (groups run one at a time per thread).
    std::vector<Vec3f> x_;
    std::vector<strand::Contact> contact_;
    unsigned loadedVersion_ = ~0u;  ///< set_.version the nodes were last synchronised with
};

RopeGroup::RopeGroup(GuideSet& set, size_t begin, size_t end) : GuideGroup(set, begin, end) {
    const GuideSettings& s = set.settings;
    btSoftBodyWorldInfo& info = world_.getWorldInfo();
    info.m_gravity = bt(s.gravity);
    info.air_density = 0;  // no aerodynamics: damping is ours, step-size independent
    info.water_density = 0;
    world_.setGravity(bt(s.gravity));
    const int n = set.vertices;
    x_.resize(n);
    contact_.resize(n);
    std::vector<btVector3> pos(n);
    std::vector<btScalar> mass(n);
    for (size_t g = begin; g < end; ++g) {
        for (int i = 0; i < n; ++i) {
            pos[i] = bt(set.x[set.vertex(g, i)]);
            mass[i] = set.mass[set.vertex(g, i)];  // root: 0 = kinematic
        }
        // Bullet fixes link rest lengths from the node positions at a body's
        // first step (m_bUpdateRtCst); settle them now, from the rest shape,
        // so a solver restored from a checkpoint before its first step keeps
        // the rest lengths of the run that saved it.
        auto* body = new btSoftBody(&info, n, pos.data(), mass.data());
        for (int j = 0; j < set.segments; ++j) body->appendLink(j, j + 1);
        body->updateConstants();
        body->m_bUpdateRtCst = false;
        btSoftBody::Config& cfg = body->m_cfg;
        cfg.piterations = 0;  // the link iterations run in StrandSoftBodySolver, with the limits
        cfg.viterations = 0;
        cfg.diterations = 0;
        cfg.kDP = 0;          // damping is applied by the kernels, exp(-c·h)
        cfg.collisions = 0;   // head contact is the signed-distance projection
        cfg.m_psequence.clear();
        cfg.m_psequence.push_back(btSoftBody::ePSolver::Linear);
        body->setActivationState(DISABLE_DEACTIVATION);
        body->setUserIndex(int(g));
        // Bullet keeps a tree of node boxes per rope, refitted each step; a
        // wide margin lets a node move centimetres before its box is re-inserted.
        body->getCollisionShape()->setMargin(0.05f);
        // Mask 0: the broadphase never pairs a rope with anything, so a world's
        // cost is linear in its guides.
        world_.addSoftBody(body, btBroadphaseProxy::DefaultFilter, 0);
        bodies_.push_back(body);
    }
}

RopeGroup::~RopeGroup() {
    for (btSoftBody* b : bodies_) {
        world_.removeSoftBody(b);
        delete b;
    }
}

void RopeGroup::reset() {
    for (size_t g = begin_; g < end_; ++g) {
        set_.restShape(g, set_.rootPos1[g], set_.rootRot1[g].toRotationMatrix(), &set_.x[set_.vertex(g, 0)]);
        for (int i = 0; i < set_.vertices; ++i) set_.v[set_.vertex(g, i)] = Vec3f::Zero();
    }
}

void RopeGroup::load(size_t g, float h, float alpha) {
    btSoftBody* body = bodies_[g - begin_];
    // The nodes already hold the state relax() stored, unless something else
    // (a reset, strand-strand contacts) wrote the shared arrays since.
    if (loadedVersion_ != set_.version) {
        for (int i = 0; i < set_.vertices; ++i) {
            btSoftBody::Node& node = body->m_nodes[i];
            node.m_x = bt(set_.x[set_.vertex(g, i)]);
            node.m_v = bt(set_.v[set_.vertex(g, i)]);
        }
    }
    // The massless root moves to its target by velocity during
    // predictMotion, so head motion enters the strand as real velocity.
    body->m_nodes[0].m_v = bt((set_.rootPosition(g, alpha) - set_.x[set_.vertex(g, 0)]) / h);
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
    world_.stepSimulation(ctx.h, 0, ctx.h);
    loadedVersion_ = ~set_.version;  // the nodes hold the probe step, not the state
}

void RopeGroup::substep(const SubstepContext& ctx) {
    loadAll(ctx.h, ctx.alpha);
    softSolver_.prepare(strand::JointPass::Drive, ctx);
    world_.stepSimulation(ctx.h, 0, ctx.h);
    for (size_t g = begin_; g < end_; ++g) relax(g, ctx);
}

void RopeGroup::relax(size_t g, const SubstepContext& ctx) {
    const GuideSettings& s = set_.settings;
    const float h = ctx.h;
    const strand::HeadQuery* head = ctx.headCollision && ctx.head.collider ? &ctx.head : nullptr;
    btSoftBody* body = bodies_[g - begin_];
    const int n = set_.vertices;
    for (int i = 0; i < n; ++i) x_[i] = ei(body->m_nodes[i].m_x);
    x_[0] = set_.rootPosition(g, ctx.alpha);
    strand::relaxJoints(strand::JointPass::Finish, x_.data(), n, set_.rootRotation(g, ctx.alpha).toRotationMatrix(),
                        set_.joints(g), head, s.collisionRadius, contact_.data());

    // Velocities from positions (position-based dynamics), then friction
    // against the moving head and step-size independent damping.
    const float damp = strand::dampingFactor(s.damping, h);
    for (int i = 0; i < n; ++i) {
        const size_t k = set_.vertex(g, i);
        Vec3f v = (x_[i] - set_.x[k]) / h;
        if (i > 0) {
            if (contact_[i].active)
                v = strand::contactFriction(v, ctx.head.surfaceVelocity(x_[i], h), contact_[i], s.friction, h);
            v *= damp;
        }
        set_.x[k] = x_[i];
        set_.v[k] = v;
        body->m_nodes[i].m_x = bt(x_[i]);
        body->m_nodes[i].m_v = bt(v);
    }
}

double RopeGroup::kineticEnergy() const {
    double e = 0;
    for (size_t g = begin_; g < end_; ++g)
        for (int i = 1; i < set_.vertices; ++i) {
            const size_t k = set_.vertex(g, i);
            e += 0.5 * set_.mass[k] * set_.v[k].squaredNorm();
        }
    return e;
}

void RopeGroup::jointAngles(float& bend, float& twist) const {
    bend = 0.f;
    twist = 0.f;
    for (size_t g = begin_; g < end_; ++g)
        bend = std::max(bend, maxBendAngle(set_, g, &set_.x[set_.vertex(g, 0)], set_.rootRot1[g]));
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
