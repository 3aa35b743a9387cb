// The one place where hair types meet Bullet's: converters between Eigen and
// Bullet values, and the soft-body rope world both Bullet strand models
// (the guides' rope, sim/guides/rope_group.cpp, and the curly guides,
// sim/curly/curly_world.cpp) are built on.
//
// Include it only from .cpp files: it pulls in Bullet's headers, which stay
// out of every header the rest of hp_sim, render/ or pipeline/ sees.
#pragma once

#include "sim/strands/strand.h"

#include <BulletSoftBody/btDefaultSoftBodySolver.h>
#include <BulletSoftBody/btSoftBody.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Geometry>

namespace hp::bullet {

/// @brief An Eigen vector as Bullet's.
inline btVector3 bt(const Vec3f& v) { return btVector3(v.x(), v.y(), v.z()); }
/// @brief A Bullet vector as Eigen's.
inline Vec3f ei(const btVector3& v) { return Vec3f(float(v.x()), float(v.y()), float(v.z())); }
/// @brief An Eigen quaternion as Bullet's (Bullet stores x, y, z, w).
inline btQuaternion bt(const Eigen::Quaternionf& q) { return btQuaternion(q.x(), q.y(), q.z(), q.w()); }
/// @brief A Bullet quaternion as Eigen's (Eigen's constructor takes w first).
inline Eigen::Quaternionf ei(const btQuaternion& q) { return Eigen::Quaternionf(q.w(), q.x(), q.y(), q.z()); }
/// @brief A rigid transform as Bullet's, its rotation matrix copied as is.
inline btTransform bt(const Eigen::Isometry3f& t) {
    const Eigen::Matrix3f& r = t.linear();
    const btMatrix3x3 basis(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2));
    return btTransform(basis, bt(Vec3f(t.translation())));
}

/// @brief Collision pools for a world whose bodies never collide: Bullet
/// preallocates ~4 MB of contact pools per world by default.
inline btDefaultCollisionConstructionInfo smallPools() {
    btDefaultCollisionConstructionInfo info;
    info.m_defaultMaxPersistentManifoldPoolSize = 16;
    info.m_defaultMaxCollisionAlgorithmPoolSize = 16;
    return info;
}

/// @brief A btSoftRigidDynamicsWorld of ropes that touch nothing: Bullet
/// integrates gravity and solves the inextensible links; collisions (with the
/// head, between strands) are the strand models' own, so every rope is added
/// with collision mask 0 and the world's cost is linear in its ropes. No air
/// or water: damping is the model's, step-size independent.
class RopeWorld {
  public:
    /// @param gravity  m/s²
    /// @param softSolver  the soft-body solver that steps the ropes (owned by the caller, outliving the world)
    /// @param pools  the collision configuration's pool sizes
    RopeWorld(const Vec3f& gravity, btSoftBodySolver* softSolver,
              const btDefaultCollisionConstructionInfo& pools = btDefaultCollisionConstructionInfo())
        : config_(pools), world_(&dispatcher_, &broadphase_, &solver_, &config_, softSolver) {
        btSoftBodyWorldInfo& info = world_.getWorldInfo();
        info.m_gravity = bt(gravity);
        info.air_density = 0;
        info.water_density = 0;
        world_.setGravity(bt(gravity));
    }
    RopeWorld(const RopeWorld&) = delete;
    RopeWorld& operator=(const RopeWorld&) = delete;

    /// @brief What a new btSoftBody of this world is built with.
    btSoftBodyWorldInfo& info() { return world_.getWorldInfo(); }

    /// @brief Configures `body` as a rope of this world and adds it: link rest
    /// lengths settled now from its nodes (Bullet would take them at the first
    /// step, m_bUpdateRtCst, so a solver restored from a checkpoint before its
    /// first step keeps the rest lengths of the run that saved it); only the
    /// linear (link) solver, `linkIterations` passes of it; no Bullet damping,
    /// no Bullet collisions, never deactivated; collision mask 0.
    void addRope(btSoftBody* body, int linkIterations) {
        body->updateConstants();
        body->m_bUpdateRtCst = false;
        btSoftBody::Config& cfg = body->m_cfg;
        cfg.piterations = linkIterations;
        cfg.viterations = 0;
        cfg.diterations = 0;
        cfg.kDP = 0;
        cfg.collisions = 0;
        cfg.m_psequence.clear();
        cfg.m_psequence.push_back(btSoftBody::ePSolver::Linear);
        body->setActivationState(DISABLE_DEACTIVATION);
        world_.addSoftBody(body, btBroadphaseProxy::DefaultFilter, 0);
    }
    void removeRope(btSoftBody* body) { world_.removeSoftBody(body); }

    /// @brief One Bullet step of length h (no internal substeps).
    void step(float h) { world_.stepSimulation(h, 0, h); }

  private:
    btSoftBodyRigidBodyCollisionConfiguration config_;
    btCollisionDispatcher dispatcher_{&config_};
    btDbvtBroadphase broadphase_;
    btSequentialImpulseConstraintSolver solver_;
    btSoftRigidDynamicsWorld world_;
};

}  // namespace hp::bullet
