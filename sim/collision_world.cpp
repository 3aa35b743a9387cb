#include "sim/collision_world.h"

#include "core/errors.h"

#include <btBulletCollisionCommon.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>

#include <limits>

namespace hp {

namespace {

btVector3 bt(const Vec3f& v) { return btVector3(v.x(), v.y(), v.z()); }
Vec3f hv(const btVector3& v) { return Vec3f(float(v.x()), float(v.y()), float(v.z())); }

btTransform bt(const Eigen::Isometry3f& t) {
    const Eigen::Matrix3f& r = t.linear();
    btMatrix3x3 basis(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2));
    return btTransform(basis, bt(Vec3f(t.translation())));
}

/// Margin of boxes and hulls: GJK treats a shape as its core grown by the
/// margin (rounded edges of this radius), so keep it far below hair scale.
constexpr float kMargin = 1e-4f;

std::unique_ptr<btConvexShape> makeShape(const ColliderShape& s) {
    switch (s.kind) {
        case ColliderShape::Kind::Sphere: return std::make_unique<btSphereShape>(s.radius);
        case ColliderShape::Kind::Capsule: return std::make_unique<btCapsuleShape>(s.radius, s.length);
        case ColliderShape::Kind::Box: {
            auto box = std::make_unique<btBoxShape>(bt(s.halfExtents));
            // btBoxShape keeps its extents and moves the margin inside.
            box->setMargin(std::min(kMargin, s.halfExtents.minCoeff()));
            return box;
        }
        case ColliderShape::Kind::ConvexMesh: {
            if (s.points.size() < 4) throw Error("collision world: a convex mesh needs at least 4 vertices");
            auto hull = std::make_unique<btConvexHullShape>();
            for (const Vec3f& p : s.points) hull->addPoint(bt(p), false);
            hull->recalcLocalAabb();
            hull->optimizeConvexHull();
            hull->setMargin(kMargin);
            return hull;
        }
    }
    throw Error("collision world: unknown shape");
}

}  // namespace

struct CollisionWorld::Impl {
    std::vector<std::unique_ptr<btConvexShape>> shapes;
    // Shared by every posed world. Only queries run there, never a
    // dispatch, so no collision algorithm is ever created or freed in them.
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher{&config};
};

namespace {

/// A posed world: one collision object per shape, one broadphase.
class PosedWorld final : public Collider {
  public:
    PosedWorld(std::shared_ptr<CollisionWorld::Impl> impl, const std::vector<Eigen::Isometry3f>& poses, float range)
        : impl_(std::move(impl)), world_(&impl_->dispatcher, &broadphase_, &impl_->config), range_(range) {
        const auto& shapes = impl_->shapes;
        objects_.reserve(shapes.size());
        for (size_t i = 0; i < shapes.size(); ++i) {
            auto o = std::make_unique<btCollisionObject>();
            o->setCollisionShape(shapes[i].get());
            o->setWorldTransform(bt(poses[i]));
            o->setUserIndex(int(i));
            world_.addCollisionObject(o.get());
            objects_.push_back(std::move(o));
        }
        world_.updateAabbs();
    }
    ~PosedWorld() override {
        for (auto& o : objects_) world_.removeCollisionObject(o.get());
    }

    float signedDistance(const Vec3f& p, Vec3f* normal) const override {
        // The objects whose box (grown by the range) holds p: the broadphase
        // tree's read-only traversal, safe from many threads.
        struct Near final : btBroadphaseAabbCallback {
            const btCollisionObject* hit[8];
            int count = 0;
            bool more = false;
            bool process(const btBroadphaseProxy* proxy) override {
                if (count < 8) hit[count++] = static_cast<const btCollisionObject*>(proxy->m_clientObject);
                else more = true;
                return true;
            }
        } nearby;
        const btVector3 q = bt(p), r(range_, range_, range_);
        const_cast<btDbvtBroadphase&>(broadphase_).aabbTest(q - r, q + r, nearby);
        float best = range_;
        Vec3f bestNormal = Vec3f::UnitY();
        auto test = [&](const btCollisionObject* o) {
            btGjkEpaSolver2::sResults res;
            const auto* shape = static_cast<const btConvexShape*>(o->getCollisionShape());
            const float d = float(btGjkEpaSolver2::SignedDistance(q, 0, shape, o->getWorldTransform(), res));
            if (d < best) {
                best = d;
                bestNormal = hv(res.normal);
            }
        };
        if (nearby.more) {
            for (const auto& o : objects_) test(o.get());
        } else {
            for (int i = 0; i < nearby.count; ++i) test(nearby.hit[i]);
        }
        if (normal) {
            const float len = bestNormal.norm();
            *normal = len > 1e-12f ? Vec3f(bestNormal / len) : Vec3f::UnitY();
        }
        return best;
    }

  private:
    std::shared_ptr<CollisionWorld::Impl> impl_;  // the shapes outlive this world
    btDbvtBroadphase broadphase_;
    btCollisionWorld world_;
    std::vector<std::unique_ptr<btCollisionObject>> objects_;
    float range_;
};

}  // namespace

CollisionWorld::CollisionWorld(const std::vector<ColliderShape>& shapes) : impl_(std::make_shared<Impl>()) {
    for (const ColliderShape& s : shapes) impl_->shapes.push_back(makeShape(s));
}

CollisionWorld::~CollisionWorld() = default;

size_t CollisionWorld::size() const { return impl_->shapes.size(); }

std::shared_ptr<const Collider> CollisionWorld::posed(const std::vector<Eigen::Isometry3f>& poses, float range) const {
    if (poses.size() != impl_->shapes.size())
        throw Error(cat("collision world: ", poses.size(), " poses for ", impl_->shapes.size(), " colliders"));
    return std::make_shared<PosedWorld>(impl_, poses, range);
}

float CompositeCollider::signedDistance(const Vec3f& p, Vec3f* normal) const {
    float best = std::numeric_limits<float>::infinity();
    if (head_) best = head_->signedDistance(p, normal);
    if (others_) {
        Vec3f n;
        const float d = others_->signedDistance(p, normal ? &n : nullptr);
        if (d < best) {
            best = d;
            if (normal) *normal = n;
        }
    }
    return best;
}

}  // namespace hp
