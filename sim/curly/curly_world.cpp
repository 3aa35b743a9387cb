// The curly guides' Bullet side: one btSoftRigidDynamicsWorld per group of
// guides, each guide a btSoftBody rope whose nodes are Kim 2023's particles.
//
// Division of labour per Bullet step h:
//  1. Kernels (sim/curly/curly_dynamics.h), per strand: Kim 2023's stretch, bending
//     and core springs and the wet forces (curl exaggeration, cohesion toward
//     the previous step's cohesive positions, adhesion to the head) assembled
//     into one linearly implicit step, giving each particle's Δv. It enters
//     Bullet as the node force m(Δv/h - g), Bullet adding gravity itself.
//  2. Bullet (btSoftBody::predictMotion, solveConstraints): integrates
//     (v += (g + f/m)h, x += vh) and solves the inextensible links with
//     `iterations` mass-weighted Gauss-Seidel passes, then sets v from the
//     positions. The root node has zero mass and moves to its kinematic target
//     by velocity, so head motion enters the strand as real velocity.
//  3. Kernels, root to tip: strain limiting (Selle et al.), projection out
//     of the head's signed distance keeping the collision radius clear, then
//     velocities from positions, Coulomb friction against the moving head,
//     root-to-tip velocity limiting, and Kim 2023's velocity scales ξ and ζ_i
//     (step-size independent).
//
// Why this arrangement: Kim 2023's springs are force-based, and a curl needs
// stiff ones — as explicit forces at 0.02 s they blow up (h²k/m ≈ 150 for the
// bending springs; explicit needs < 4), so they go through an implicit step,
// which Bullet's soft-body solver does not offer for such springs (its links
// and bending links are position constraints without targets that turn with
// the strand); Bullet keeps what it does well here, integration and
// inextensibility. Head contact goes through the signed distance
// (as the rigid-chain guides do, and as Kim 2023's adhesion needs anyway)
// rather than Bullet's soft-rigid sparse SDF, whose cell (0.25 m by default,
// ~5 mm needed for a head) and per-step btSparseSdf::GarbageCollect (~22% of
// a rope step in a probe at 845 strands) buy nothing for a single smooth head.
// Worlds have no broadphase pairs (collision mask 0), so a world's cost is
// linear in its guides and worlds run in parallel.
#include "sim/collision/bullet_adapter.h"
#include "sim/curly/curly_state.h"

#include <cmath>

namespace hp::curly {
namespace {

using bullet::bt;
using bullet::ei;

class BulletCurlyWorld final : public CurlyWorld {
  public:
    BulletCurlyWorld(CurlySet& set, size_t begin, size_t end);
    ~BulletCurlyWorld() override;
    GroupCounters substep(const SubstepContext& ctx) override;
    size_t begin() const override { return begin_; }
    size_t end() const override { return end_; }

  private:
    bool load(size_t g, const SubstepContext& ctx, size_t& adhesion);
    void finish(size_t g, const SubstepContext& ctx);

    CurlySet& set_;
    size_t begin_, end_;
    btDefaultSoftBodySolver softSolver_;
    bullet::RopeWorld world_{set_.settings.gravity, &softSolver_};
    std::vector<btSoftBody*> bodies_;
    // Scratch for one strand, reused (a group runs on one thread at a time).
    StrandScratch scratch_;
    std::vector<Vec3f> dv_, accel_, x_, v_;
    std::vector<float> len_;
    std::vector<Contact> contact_;
};

BulletCurlyWorld::BulletCurlyWorld(CurlySet& set, size_t begin, size_t end) : set_(set), begin_(begin), end_(end) {
    const CurlyWetSettings& s = set.settings;
    const int n = set.n;
    std::vector<btVector3> pos(n);
    std::vector<btScalar> mass(n);
    for (size_t g = begin; g < end; ++g) {
        for (int i = 0; i < n; ++i) {
            pos[i] = bt(set.x[set.particle(g, i)]);
            mass[i] = i == 0 ? 0.f : set.mass[set.particle(g, i)];  // root: kinematic
        }
        // Link rest lengths from the rest shape (initialize puts every guide
        // there); damping is Kim 2023's springs and ξ, ζ; head contact the
        // signed-distance projection.
        auto* body = new btSoftBody(&world_.info(), n, pos.data(), mass.data());
        for (int j = 0; j + 1 < n; ++j) body->appendLink(j, j + 1);
        world_.addRope(body, s.iterations);
        bodies_.push_back(body);
    }
    scratch_.resize(size_t(n));
    dv_.resize(n);
    accel_.resize(n);
    x_.resize(n);
    v_.resize(n);
    len_.resize(n);
    contact_.resize(n);
}

BulletCurlyWorld::~BulletCurlyWorld() {
    for (btSoftBody* b : bodies_) {
        world_.removeRope(b);
        delete b;
    }
}

bool BulletCurlyWorld::load(size_t g, const SubstepContext& ctx, size_t& adhesion) {
    const CurlyWetSettings& s = set_.settings;
    const int n = set_.n;
    const size_t k0 = set_.particle(g, 0);
    const Vec3f* x = &set_.x[k0];
    const Vec3f* v = &set_.v[k0];
    const float* sigma = set_.wet ? &set_.sigma[k0] : nullptr;
    const Vec3f rootVel = (set_.rootPosition(g, ctx.alpha) - x[0]) / ctx.h;
    const Mat3f R = set_.rootRotation(g, ctx.alpha).toRotationMatrix();

    StrandLoads loads;
    loads.sigma = sigma;
    if (sigma && !set_.cohesion.empty()) loads.cohesion = &set_.cohesion[k0];
    if (sigma && s.adhesion && ctx.head.collider) {
        for (int i = 0; i < n; ++i) {
            accel_[i].setZero();
            if (i == 0 || !(sigma[i] > 0.f)) continue;
            // Evaluated where the particle will be at the step's end if it
            // keeps its velocity: the shell (h/2, h] is thinner than a step's
            // travel at hair speeds, so a particle leaving the head must feel
            // the pull in the step it crosses the shell, not after.
            Vec3f normal;
            const float phi = ctx.head.distance(x[i] + ctx.h * v[i], &normal);
            accel_[i] = adhesionAcceleration(phi, normal, sigma[i], s.adhesionWeight, s.adhesionRadius);
            if (accel_[i].squaredNorm() > 0.f) ++adhesion;
        }
        loads.acceleration = accel_.data();
    }
    const bool ok = implicitStep(x, v, size_t(n), R, rootVel, set_.rest(g), set_.coefficients, loads, ctx.h,
                                 scratch_, dv_.data());

    btSoftBody* body = bodies_[g - begin_];
    for (int i = 0; i < n; ++i) {
        btSoftBody::Node& node = body->m_nodes[i];
        node.m_x = bt(x[i]);
        node.m_v = bt(v[i]);
        node.m_f = btVector3(0, 0, 0);
    }
    body->m_nodes[0].m_v = bt(rootVel);
    if (ok) {
        const Vec3f g0 = s.gravity;
        for (int i = 1; i < n; ++i) {
            const float m = set_.mass[k0 + size_t(i)];
            body->addForce(bt(m * (dv_[i] / ctx.h - g0)), i);
        }
    }
    return ok;
}

void BulletCurlyWorld::finish(size_t g, const SubstepContext& ctx) {
    const CurlyWetSettings& s = set_.settings;
    const float h = ctx.h;
    const int n = set_.n;
    const size_t k0 = set_.particle(g, 0);
    const btSoftBody* body = bodies_[g - begin_];
    const float* rest = &set_.edgeLength[set_.edge(g, 0)];
    for (int i = 0; i < n; ++i) x_[i] = ei(body->m_nodes[i].m_x);
    for (int i = 1; i < n; ++i) len_[i - 1] = strainLimited((x_[i] - x_[i - 1]).norm(), rest[i - 1], s.maxStrain);
    x_[0] = set_.rootPosition(g, ctx.alpha);
    // Strain limit and head clearance, root to tip, keeping the edge lengths
    // Bullet left (within the limit); the head has the last word.
    contact_[0] = Contact{};
    for (int i = 1; i < n; ++i)
        contact_[i] = placeParticle(x_[i - 1], x_[i], len_[i - 1], ctx.head, s.collisionRadius);
    // Velocities from positions, friction, velocity limiting, ξ and ζ.
    for (int i = 0; i < n; ++i)
        v_[i] = strand::stepVelocity(set_.x[k0 + size_t(i)], x_[i], h, contact_[i], ctx.head, s.friction);
    limitRelativeVelocity(v_.data(), size_t(n), s.maxRelativeVelocity);
    const float xi = perStepFactor(s.globalStiffness, h, s.stiffnessStep);
    for (int i = 1; i < n; ++i) {
        float scale = xi;
        if (set_.wet) {
            const float zeta = wetVelocityFactor(set_.sigma[k0 + size_t(i)], s.wetStiffness, s.dryStiffness);
            scale *= perStepFactor(zeta, h, s.stiffnessStep);
        }
        v_[i] *= scale;
    }
    for (int i = 0; i < n; ++i) {
        set_.x[k0 + size_t(i)] = x_[i];
        set_.v[k0 + size_t(i)] = v_[i];
    }
}

GroupCounters BulletCurlyWorld::substep(const SubstepContext& ctx) {
    GroupCounters c;
    for (size_t g = begin_; g < end_; ++g)
        if (!load(g, ctx, c.adhesion)) ++c.failed;
    world_.step(ctx.h);
    for (size_t g = begin_; g < end_; ++g) finish(g, ctx);
    return c;
}

}  // namespace

void CurlySet::resetGuide(size_t g) {
    const Mat3f R = rootRot1[g].toRotationMatrix();
    for (int i = 0; i < n; ++i) {
        const size_t k = particle(g, i);
        x[k] = rootPos1[g] + R * restLocal[k];
        v[k] = Vec3f::Zero();
    }
}

std::unique_ptr<CurlyWorld> makeCurlyWorld(CurlySet& set, size_t begin, size_t end) {
    return std::make_unique<BulletCurlyWorld>(set, begin, end);
}

}  // namespace hp::curly
