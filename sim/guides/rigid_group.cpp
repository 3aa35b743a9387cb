// Gomes 2024's own formulation, kept faithful: a guide is a chain of capsule
// btRigidBody segments, each joined to its parent (the previous segment, or
// a kinematic root body moved with the scalp) at the end of the parent by a
// btGeneric6DofSpring2Constraint, Bullet's closest analogue of Unity's
// ConfigurableJoint:
//  - linear motion locked (lower = upper = 0 on the three linear axes);
//  - angular limits ±bendLimit about the two bending axes (X, Z) and
//    ±twistLimit about the segment's own axis (Y; Euler order XYZ keeps the
//    middle axis the limited-to-±90° one); limits are soft through Bullet's
//    stop ERP, i.e. pushed back over several steps;
//  - springs toward the rest pose on the three angular axes (stiffness κ,
//    damping), their equilibrium points shifted by the gravity pre-load;
//  - a projection limit (Unity's projection): after each step a joint
//    separated by more than `projectionDistance` segments, or bent beyond its
//    limit by more than `projectionAngle`, is snapped back;
//  - the head is a kinematic body with a triangle-mesh shape (discrete
//    contacts; Bullet multiplies two bodies' frictions, so each gets sqrt(μ) and
//    every pair gets μ = 0.2, as Unity's "average" gives for one material);
//  - damping through btRigidBody::setDamping, whose v·(1-d)^h is exp(-c·h)
//    for d = 1 - exp(-c), so step-size independent.
// With strand-strand collision on, all guides share one world (capsules of
// different guides collide), as in Gomes 2024; otherwise each world holds
// `strandsPerWorld` guides and the capsules collide only with the head.
// Optional position-level projection out of the head's signed distance is
// applied to the segment bodies (settings.headCollision), as in the rope.
//
// What it does, measured (B-sim): Bullet's 6-DoF springs are explicit and
// capped for stability by the bodies' inertia (for 1 mm capsules ~3e-7
// N·m/rad), so the chains hang on their limits and the pre-load cannot hold
// the rest shape; a plain chain at one step per 0.02 s breaks its limits
// (100°+) and tears (checked without the projection), so the projection limit
// does the holding and the chains jitter at its bounds — Gomes 2024's "chaotic
// effects"; segment ends drift apart by up to ~0.6 segment between
// projections; ~27 ms/step for 94 guides, ~155 for 845 on one core.
#include "sim/collision/bullet_adapter.h"
#include "sim/guides/guide_group.h"

#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace hp::guides {
namespace {

using bullet::bt;
using bullet::ei;
/// A rigid pose for Bullet's bodies: the rotation part as a quaternion
/// (Eigen's rotation(), so a pose with scale keeps only its rotation).
inline btTransform bodyPose(const Eigen::Isometry3f& t) {
    return btTransform(bt(Quatf(t.rotation())), bt(Vec3f(t.translation())));
}

constexpr int kHeadGroup = 64, kStrandGroup = 128;

/// Contact pools sized for about one head contact per segment (Bullet's
/// default preallocates 4096 of each per world; beyond the pool it allocates).
btDefaultCollisionConstructionInfo pools(int segments) {
    btDefaultCollisionConstructionInfo info;
    info.m_defaultMaxPersistentManifoldPoolSize = std::max(64, segments);
    info.m_defaultMaxCollisionAlgorithmPoolSize = std::max(64, 2 * segments);
    return info;
}

// The angles btGeneric6DofSpring2Constraint reports for RO_XYZ (its
// matrixToEulerXYZ, which reads the matrix transposed) are those of
// r = B⁻¹A for joint frames A, B: r = Rx(x)·Ry(y)·Rz(z) (checked against
// getAngle on random poses). fromEulerXYZ is the inverse.
Vec3f eulerXYZ(const Mat3f& r) {
    const float sy = std::clamp(r(0, 2), -1.f, 1.f);
    return Vec3f(std::atan2(-r(1, 2), r(2, 2)), std::asin(sy), std::atan2(-r(0, 1), r(0, 0)));
}
Mat3f fromEulerXYZ(const Vec3f& a) {
    return (Eigen::AngleAxisf(a.x(), Vec3f::UnitX()) * Eigen::AngleAxisf(a.y(), Vec3f::UnitY()) *
            Eigen::AngleAxisf(a.z(), Vec3f::UnitZ()))
        .toRotationMatrix();
}

/// Shapes shared by all worlds: the capsules and the head's mesh in
/// head-local coordinates (refitted when the head deforms).
struct RigidShared {
    std::map<float, std::unique_ptr<btCapsuleShape>> capsules;
    btSphereShape rootShape{0.001f};
    std::vector<btVector3> headVertices;  // head-local
    std::vector<int> headIndices;
    std::unique_ptr<btTriangleIndexVertexArray> headArray;
    std::unique_ptr<btBvhTriangleMeshShape> headShape;

    btCapsuleShape* capsule(float length, float radius) {
        auto& c = capsules[length];
        if (!c) c = std::make_unique<btCapsuleShape>(radius, std::max(length - 2.f * radius, 0.f));
        return c.get();
    }
};

class RigidGroup final : public GuideGroup {
  public:
    RigidGroup(GuideSet& set, size_t begin, size_t end, RigidShared& shared);
    ~RigidGroup() override;

    void reset() override;
    void preload(const SubstepContext& ctx) override;
    void substep(const SubstepContext& ctx) override;
    double kineticEnergy() const override;
    void jointAngles(float& bend, float& twist) const override;

  private:
    btRigidBody* segment(size_t g, int j) const { return segments_[(g - begin_) * set_.segments + j].get(); }
    btGeneric6DofSpring2Constraint* joint(size_t g, int j) const {
        return joints_[(g - begin_) * set_.segments + j].get();
    }
    void placeAtRest(size_t g);
    void moveKinematic(const SubstepContext& ctx);
    void project(size_t g, const SubstepContext& ctx);
    void readBack(size_t g);

    RigidShared& shared_;
    btDefaultCollisionConfiguration config_{pools(set_.settings.strandsPerWorld * set_.segments)};
    btCollisionDispatcher dispatcher_{&config_};
    std::unique_ptr<bt32BitAxisSweep3> broadphase_;
    btSequentialImpulseConstraintSolver solver_;
    std::unique_ptr<btDiscreteDynamicsWorld> world_;
    std::unique_ptr<btRigidBody> head_;
    std::vector<std::unique_ptr<btRigidBody>> roots_, segments_;
    std::vector<std::unique_ptr<btGeneric6DofSpring2Constraint>> joints_;
    std::vector<Mat3f> restRot_;  // per segment: world rest rotation relative to the root frame
};

RigidGroup::RigidGroup(GuideSet& set, size_t begin, size_t end, RigidShared& shared)
    : GuideGroup(set, begin, end), shared_(shared) {
    const GuideSettings& s = set.settings;
    // Sweep-and-prune: Bullet's AABB tree pads every box by 5 cm, pairing each
    // 1 cm capsule with hundreds of others; SAP needs bounds, taken around the
    // guides' start, wide enough for the head to travel (outside them it
    // still works, only slower).
    Eigen::AlignedBox3f box;
    for (size_t g = begin; g < end; ++g) box.extend(set.x[set.vertex(g, 0)]);
    box.extend(set.headTransform.translation());
    const Vec3f pad = Vec3f::Constant(2.f * s.length + 10.f);
    broadphase_ = std::make_unique<bt32BitAxisSweep3>(bt(Vec3f(box.min() - pad)), bt(Vec3f(box.max() + pad)),
                                                      unsigned((end - begin) * (set.segments + 1) + 16), nullptr, true);
    world_ = std::make_unique<btDiscreteDynamicsWorld>(&dispatcher_, broadphase_.get(), &solver_, &config_);
    world_->setGravity(bt(s.gravity));
    world_->getSolverInfo().m_numIterations = s.iterations;
    const float friction = std::sqrt(s.friction);  // Bullet multiplies the two bodies' coefficients
    const float lin = 1.f - std::exp(-s.damping);
    const float deg = float(M_PI / 180.0);

    if (shared.headShape) {
        btRigidBody::btRigidBodyConstructionInfo ci(0, nullptr, shared.headShape.get());
        head_ = std::make_unique<btRigidBody>(ci);
        head_->setCollisionFlags(head_->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
        head_->setActivationState(DISABLE_DEACTIVATION);
        head_->setFriction(friction);
        head_->setWorldTransform(bodyPose(set.headTransform));  // posed before insertion, like every body here
        head_->setInterpolationWorldTransform(bodyPose(set.headTransform));
        world_->addRigidBody(head_.get(), kHeadGroup, kStrandGroup);
    }
    for (size_t g = begin; g < end; ++g) {
        btRigidBody::btRigidBodyConstructionInfo rci(0, nullptr, &shared.rootShape);
        auto root = std::make_unique<btRigidBody>(rci);
        root->setCollisionFlags(root->getCollisionFlags() | btCollisionObject::CF_KINEMATIC_OBJECT);
        root->setActivationState(DISABLE_DEACTIVATION);
        const Mat3f rootR = set.rootRot1[g].toRotationMatrix();
        root->setWorldTransform(btTransform(bt(set.rootRot1[g]), bt(set.rootPos1[g])));
        world_->addRigidBody(root.get(), 0, 0);
        std::vector<Vec3f> rest(set.vertices);
        set.restShape(g, set.rootPos1[g], rootR, rest.data());
        // Rest rotations: each segment's local Y along its rest direction, the
        // frame carried from the root by the minimal rotation (no twist).
        Mat3f R = Mat3f::Identity();
        Vec3f prevDir = Vec3f::UnitY();
        btRigidBody* parent = root.get();
        float parentLength = 0.f;
        Mat3f parentRot = Mat3f::Identity();
        for (int j = 0; j < set.segments; ++j) {
            const size_t seg = set.segment(g, j);
            const float len = set.restLength[seg];
            const Vec3f dir = set.groomDir[seg];
            R = strand::transport(prevDir, dir).toRotationMatrix() * R;
            prevDir = dir;
            restRot_.push_back(R);
            const float m = set.settings.massPerLength * len;
            btCapsuleShape* shape = shared.capsule(len, s.collisionRadius);
            btVector3 inertia;
            shape->calculateLocalInertia(m, inertia);
            // A 1 mm capsule's inertia about its own axis is ~100× below the
            // others; Bullet's joint solver then spins it up (twist at its
            // limit, energy growing). The axial inertia is raised to the
            // transverse one, as physics engines recommend for thin bodies.
            inertia.setY(inertia.x());
            btRigidBody::btRigidBodyConstructionInfo ci(m, nullptr, shape, inertia);
            auto body = std::make_unique<btRigidBody>(ci);
            body->setActivationState(DISABLE_DEACTIVATION);
            body->setFriction(friction);
            body->setDamping(lin, lin);
            // Posed before insertion: bodies all at the origin would first
            // pair every capsule with every other.
            body->setWorldTransform(btTransform(bt(Quatf(rootR * R)), bt(Vec3f(0.5f * (rest[j] + rest[j + 1])))));
            world_->addRigidBody(body.get(), kStrandGroup, kHeadGroup | (s.strandCollision ? kStrandGroup : 0));
            // Joint frames: at the parent's far end and this segment's near
            // end, oriented so the rest pose is the zero of every angle.
            btTransform frameA, frameB;
            frameA.setIdentity();
            frameB.setIdentity();
            frameA.setOrigin(btVector3(0, 0.5f * parentLength, 0));
            const Quatf rel(parentRot.transpose() * R);
            frameA.setRotation(bt(rel));
            frameB.setOrigin(btVector3(0, -0.5f * len, 0));
            auto jt = std::make_unique<btGeneric6DofSpring2Constraint>(*parent, *body, frameA, frameB, RO_XYZ);
            jt->setLinearLowerLimit(btVector3(0, 0, 0));
            jt->setLinearUpperLimit(btVector3(0, 0, 0));
            jt->setAngularLowerLimit(btVector3(-s.bendLimit, -s.twistLimit, -s.bendLimit) * deg);
            jt->setAngularUpperLimit(btVector3(s.bendLimit, s.twistLimit, s.bendLimit) * deg);
            for (int a = 3; a < 6; ++a) {
                jt->enableSpring(a, s.bendStiffness > 0.f);
                jt->setStiffness(a, s.bendStiffness);  // Bullet limits it to what its explicit spring can take
                jt->setDamping(a, s.bendDamping);
                jt->setEquilibriumPoint(a, 0);
            }
            world_->addConstraint(jt.get(), true);
            parent = body.get();
            parentLength = len;
            parentRot = R;
            segments_.push_back(std::move(body));
            joints_.push_back(std::move(jt));
        }
        roots_.push_back(std::move(root));
    }
    reset();
}

RigidGroup::~RigidGroup() {
    for (auto& j : joints_) world_->removeConstraint(j.get());
    for (auto& b : segments_) world_->removeRigidBody(b.get());
    for (auto& b : roots_) world_->removeRigidBody(b.get());
    if (head_) world_->removeRigidBody(head_.get());
}

void RigidGroup::placeAtRest(size_t g) {
    const Mat3f R = set_.rootRot1[g].toRotationMatrix();
    const Vec3f p = set_.rootPos1[g];
    btTransform rootT(bt(set_.rootRot1[g]), bt(p));
    btRigidBody* root = roots_[g - begin_].get();
    root->setWorldTransform(rootT);
    root->setInterpolationWorldTransform(rootT);
    set_.restShape(g, p, R, &set_.x[set_.vertex(g, 0)]);
    for (int j = 0; j < set_.segments; ++j) {
        const Vec3f c = 0.5f * (set_.x[set_.vertex(g, j)] + set_.x[set_.vertex(g, j + 1)]);
        const Quatf q(R * restRot_[(g - begin_) * set_.segments + j]);
        btRigidBody* b = segment(g, j);
        const btTransform t(bt(q), bt(c));
        b->setWorldTransform(t);
        b->setInterpolationWorldTransform(t);
        b->setLinearVelocity(btVector3(0, 0, 0));
        b->setAngularVelocity(btVector3(0, 0, 0));
        b->clearForces();
    }
    for (int i = 0; i < set_.vertices; ++i) set_.v[set_.vertex(g, i)] = Vec3f::Zero();
}

void RigidGroup::reset() {
    if (head_) {
        head_->setWorldTransform(bodyPose(set_.headTransform));
        head_->setInterpolationWorldTransform(bodyPose(set_.headTransform));
    }
    for (size_t g = begin_; g < end_; ++g) placeAtRest(g);
}

void RigidGroup::moveKinematic(const SubstepContext& ctx) {
    // Kinematic bodies get their velocity from the change of transform in
    // btRigidBody::saveKinematicState, so the contacts see the real motion.
    for (size_t g = begin_; g < end_; ++g)
        roots_[g - begin_]->setWorldTransform(
            btTransform(bt(set_.rootRotation(g, ctx.alpha)), bt(set_.rootPosition(g, ctx.alpha))));
    if (head_) head_->setWorldTransform(bodyPose(ctx.headTransform));
}

void RigidGroup::preload(const SubstepContext& ctx) {
    // Inverse statics by iteration: let the chains settle at rest under
    // gravity with strong damping, move each spring's equilibrium point
    // against the angle it settled at (clamped to the limits), start again.
    const GuideSettings& s = set_.settings;
    if (s.bendStiffness <= 0.f) return;
    const float deg = float(M_PI / 180.0);
    const float settleDamping = 1.f - std::exp(-20.f);
    for (auto& b : segments_) b->setDamping(settleDamping, settleDamping);
    for (int round = 0; round < 3; ++round) {
        reset();
        moveKinematic(ctx);
        for (int k = 0; k < 40; ++k) world_->stepSimulation(ctx.h, 0, ctx.h);
        for (auto& jt : joints_) {
            jt->calculateTransforms();
            for (int a = 0; a < 3; ++a) {
                const float lim = (a == 1 ? s.twistLimit : s.bendLimit) * deg;
                auto* motor = jt->getRotationalLimitMotor(a);
                const float eq = std::clamp(float(motor->m_equilibriumPoint - jt->getAngle(a)), -lim, lim);
                jt->setEquilibriumPoint(a + 3, eq);
            }
        }
    }
    const float lin = 1.f - std::exp(-s.damping);
    for (auto& b : segments_) b->setDamping(lin, lin);
    reset();
}

void RigidGroup::substep(const SubstepContext& ctx) {
    moveKinematic(ctx);
    world_->stepSimulation(ctx.h, 0, ctx.h);
    for (size_t g = begin_; g < end_; ++g) {
        project(g, ctx);
        readBack(g);
    }
}

void RigidGroup::project(size_t g, const SubstepContext& ctx) {
    const GuideSettings& s = set_.settings;
    const float deg = float(M_PI / 180.0);
    btRigidBody* parent = roots_[g - begin_].get();
    for (int j = 0; j < set_.segments; ++j) {
        btRigidBody* body = segment(g, j);
        btGeneric6DofSpring2Constraint* jt = joint(g, j);
        const float len = set_.restLength[set_.segment(g, j)];
        // Projection limit (Unity's projection): a joint bent or twisted past
        // its limit by more than projectionAngle is turned back to that, and a
        // joint pulled apart by more than projectionDistance is closed, by
        // re-posing the child body about the parent's joint frame.
        const btTransform fa = parent->getWorldTransform() * jt->getFrameOffsetA();
        const btTransform fb = body->getWorldTransform() * jt->getFrameOffsetB();
        const Mat3f A = ei(fa.getRotation()).toRotationMatrix();
        const Mat3f B = ei(fb.getRotation()).toRotationMatrix();
        const Vec3f angles = eulerXYZ(B.transpose() * A);
        const Vec3f limit = Vec3f(s.bendLimit, s.twistLimit, s.bendLimit) * deg;
        const Vec3f reach = limit + Vec3f::Constant(s.projectionAngle * deg);
        const Vec3f clamped = angles.cwiseMax(-reach).cwiseMin(reach);
        const Vec3f anchorA = ei(fa.getOrigin());
        const bool bent = clamped != angles;
        if (bent || (ei(fb.getOrigin()) - anchorA).norm() > s.projectionDistance * len) {
            const Mat3f Bp = bent ? Mat3f(A * fromEulerXYZ(clamped).transpose()) : B;
            // Frame B has the identity rotation, so the body's rotation is Bp.
            const Vec3f centre = anchorA + Bp * Vec3f(0, 0.5f * len, 0);
            body->setWorldTransform(btTransform(bt(Quatf(Bp)), bt(centre)));
        }
        // Head projection (signed distance), both ends and the middle.
        if (ctx.collidingHead()) {
            const btTransform& t = body->getWorldTransform();
            const Vec3f c = ei(t.getOrigin()), axis = ei(t.getBasis().getColumn(1));
            strand::Contact deepest;
            for (float u : {-0.5f, 0.f, 0.5f}) {
                Vec3f p = c + u * len * axis;
                const strand::Contact k = strand::projectOut(ctx.head, s.collisionRadius, p);
                if (k.active && k.push > deepest.push) deepest = k;
            }
            if (deepest.active) {
                btTransform moved2 = t;
                moved2.setOrigin(t.getOrigin() + bt(deepest.push * deepest.normal));
                body->setWorldTransform(moved2);
                const Vec3f v = ei(body->getLinearVelocity());
                const Vec3f vs = ctx.head.surfaceVelocity(c, ctx.h);
                // The push did not come from the velocity here: no push/h term.
                strand::Contact k = deepest;
                k.push = 0.f;
                body->setLinearVelocity(bt(strand::contactFriction(v, vs, k, s.friction, ctx.h)));
            }
        }
        parent = body;
    }
}

void RigidGroup::readBack(size_t g) {
    set_.x[set_.vertex(g, 0)] = ei(roots_[g - begin_]->getWorldTransform().getOrigin());
    set_.v[set_.vertex(g, 0)] = ei(roots_[g - begin_]->getLinearVelocity());
    for (int j = 0; j < set_.segments; ++j) {
        const btRigidBody* b = segment(g, j);
        const btTransform& t = b->getWorldTransform();
        const btVector3 tip = t * btVector3(0, 0.5f * set_.restLength[set_.segment(g, j)], 0);
        set_.x[set_.vertex(g, j + 1)] = ei(tip);
        set_.v[set_.vertex(g, j + 1)] = ei(b->getVelocityInLocalPoint(tip - t.getOrigin()));
    }
}

double RigidGroup::kineticEnergy() const {
    double e = 0;
    for (const auto& b : segments_) {
        const btVector3 w = b->getAngularVelocity();
        const btVector3 Iw = b->getInvInertiaTensorWorld().inverse() * w;
        e += 0.5 * (b->getLinearVelocity().length2() / b->getInvMass() + w.dot(Iw));
    }
    return e;
}

void RigidGroup::jointAngles(float& bend, float& twist) const {
    bend = twist = 0.f;
    for (const auto& jt : joints_) {
        jt->calculateTransforms();
        bend = std::max({bend, std::abs(float(jt->getAngle(0))), std::abs(float(jt->getAngle(2)))});
        twist = std::max(twist, std::abs(float(jt->getAngle(1))));
    }
}

class RigidFormulation final : public Formulation {
  public:
    explicit RigidFormulation(const HeadPose& head) {
        useHairScaleContactThreshold();
        if (head.mesh.triangles.empty()) return;
        const Eigen::Isometry3f toLocal = head.transform.inverse();
        for (const Vec3f& p : head.mesh.positions) shared_.headVertices.push_back(bt(toLocal * p));
        for (const Tri& t : head.mesh.triangles)
            for (uint32_t i : t) shared_.headIndices.push_back(int(i));
        shared_.headArray = std::make_unique<btTriangleIndexVertexArray>(
            int(head.mesh.triangles.size()), shared_.headIndices.data(), 3 * sizeof(int),
            int(shared_.headVertices.size()), &shared_.headVertices[0][0], sizeof(btVector3));
        shared_.headShape = std::make_unique<btBvhTriangleMeshShape>(shared_.headArray.get(), true);
    }

    std::unique_ptr<GuideGroup> makeGroup(GuideSet& set, size_t begin, size_t end) override {
        return std::make_unique<RigidGroup>(set, begin, end, shared_);
    }

    void beginStep(const HeadPose& head) override {
        // A deforming head: refit the shared mesh (in head-local coordinates,
        // so a rigid motion alone changes nothing here).
        if (!shared_.headShape || head.mesh.positions.size() != shared_.headVertices.size()) return;
        const Eigen::Isometry3f toLocal = head.transform.inverse();
        bool changed = false;
        for (size_t i = 0; i < head.mesh.positions.size(); ++i) {
            const btVector3 p = bt(toLocal * head.mesh.positions[i]);
            if ((p - shared_.headVertices[i]).length2() > 1e-12f) {
                shared_.headVertices[i] = p;
                changed = true;
            }
        }
        if (!changed) return;
        btVector3 lo(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT), hi = -lo;
        for (const btVector3& p : shared_.headVertices) {
            lo.setMin(p);
            hi.setMax(p);
        }
        shared_.headShape->refitTree(lo, hi);
    }

  private:
    RigidShared shared_;
};

}  // namespace

std::unique_ptr<Formulation> makeRigidFormulation(const GuideSet&, const HeadPose& head) {
    return std::make_unique<RigidFormulation>(head);
}

}  // namespace hp::guides
