#include "sim/collision/collision_world.h"

#include "core/errors.h"
#include "sim/collision/bullet_adapter.h"

#include <btBulletCollisionCommon.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>

#include <limits>

namespace hp {

namespace {

using bullet::bt;
using bullet::ei;

/// Margin of boxes and hulls: GJK treats a shape as its core grown by the
/// margin (rounded edges of this radius), so keep it far below hair scale.
constexpr float kMargin = 1e-4f;

std::unique_ptr<btCollisionShape> makeShape(const ColliderShape& s) {
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
        case ColliderShape::Kind::SkinnedMesh:
            if (s.triangles.empty()) throw Error("collision world: a skinned mesh needs triangles");
            return nullptr;  // built on each pose's vertices (SkinShape)
    }
    throw Error("collision world: unknown shape");
}

}  // namespace

struct CollisionWorld::Impl {
    std::vector<ColliderShape> specs;
    std::vector<std::unique_ptr<btCollisionShape>> shapes;  ///< null for skinned meshes
    // Shared by every posed world. Only queries run there, never a
    // dispatch, so no collision algorithm is ever created or freed in them.
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher{&config};
};

namespace {

/// A skinned mesh at one pose: its vertices, Bullet's view of them and the
/// BVH over them. Rebuilt per pose rather than refitted in place: several
/// poses are alive at once (a step's head and the frame's), each queried
/// from many threads.
struct SkinShape {
    std::vector<Vec3f> vertices;
    std::vector<int> indices;
    std::unique_ptr<btTriangleIndexVertexArray> array;
    std::unique_ptr<btBvhTriangleMeshShape> shape;

    SkinShape(std::vector<Vec3f> v, const std::vector<Tri>& triangles) : vertices(std::move(v)) {
        for (const Tri& t : triangles)
            for (uint32_t i : t) {
                if (i >= vertices.size()) throw Error("collision world: a skinned mesh pose misses vertices");
                indices.push_back(int(i));
            }
        static_assert(sizeof(Vec3f) == 3 * sizeof(btScalar), "Bullet reads the vertices in place");
        array = std::make_unique<btTriangleIndexVertexArray>(int(triangles.size()), indices.data(), 3 * int(sizeof(int)),
                                                             int(vertices.size()),
                                                             reinterpret_cast<btScalar*>(vertices.data()->data()),
                                                             int(sizeof(Vec3f)));
        shape = std::make_unique<btBvhTriangleMeshShape>(array.get(), true);
    }
};

/// Signed distance from `q` (mesh coordinates) to the nearest triangle of
/// `mesh` within `range`: Bullet's closest point on each candidate triangle;
/// inside when q lies behind the nearest triangle's face. At an edge or a
/// corner several triangles are nearest: the one q lies most squarely
/// above or below (largest |n·(q - c)| / |q - c|) decides the sign.
float meshDistance(const btBvhTriangleMeshShape& mesh, const btVector3& q, float range, btVector3& normal) {
    struct Nearest final : btTriangleCallback {
        btVector3 q;
        float distance = 0.f;  ///< unsigned, of the nearest triangle so far
        float square = -1.f;   ///< |n·(q - c)| / |q - c| of that triangle
        bool inside = false;
        btVector3 normal{0, 1, 0};
        void processTriangle(btVector3* t, int, int) override {
            btVector3 n = (t[1] - t[0]).cross(t[2] - t[0]);
            if (n.length2() <= 0) return;
            n.normalize();
            // Bullet's exact Voronoi-region closest point on a triangle (GJK
            // on a flat triangle stops ~10% short of it in float).
            btVoronoiSimplexSolver solver;
            btSubSimplexClosestResult closest;
            solver.closestPtPointTriangle(q, t[0], t[1], t[2], closest);
            const btVector3 e = q - closest.m_closestPointOnSimplex;
            const float len = float(e.length()), h = float(n.dot(e));
            const float sq = len > 1e-9f ? std::abs(h) / len : 1.f;
            const float dist = len;
            if (dist < distance - 1e-7f || (dist < distance + 1e-7f && sq > square)) {
                distance = dist;
                square = sq;
                inside = h < 0.f;
                normal = len > 1e-9f ? (inside ? -e / len : e / len) : n;
            }
        }
    } nearest;
    nearest.q = q;
    nearest.distance = range;
    const btVector3 r(range, range, range);
    mesh.processAllTriangles(&nearest, q - r, q + r);
    normal = nearest.normal;
    return nearest.inside ? -nearest.distance : nearest.distance;
}

/// A posed world: one collision object per shape, one broadphase.
class PosedWorld final : public Collider {
  public:
    PosedWorld(std::shared_ptr<CollisionWorld::Impl> impl, const std::vector<Eigen::Isometry3f>& poses, float range,
               std::vector<std::vector<Vec3f>> skins)
        : impl_(std::move(impl)), world_(&impl_->dispatcher, &broadphase_, &impl_->config), range_(range) {
        const auto& shapes = impl_->shapes;
        objects_.reserve(shapes.size());
        for (size_t i = 0; i < shapes.size(); ++i) {
            auto o = std::make_unique<btCollisionObject>();
            if (shapes[i]) {
                o->setCollisionShape(shapes[i].get());
            } else {
                if (i >= skins.size() || skins[i].empty())
                    throw Error(cat("collision world: no vertices for skinned collider ", i));
                skins_.push_back(std::make_unique<SkinShape>(std::move(skins[i]), impl_->specs[i].triangles));
                o->setCollisionShape(skins_.back()->shape.get());
            }
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
            const btCollisionShape* shape = o->getCollisionShape();
            const btTransform& T = o->getWorldTransform();
            float d;
            btVector3 n;
            if (shape->isConvex()) {
                btGjkEpaSolver2::sResults res;
                d = float(btGjkEpaSolver2::SignedDistance(q, 0, static_cast<const btConvexShape*>(shape), T, res));
                n = res.normal;
            } else {
                d = meshDistance(*static_cast<const btBvhTriangleMeshShape*>(shape), T.invXform(q), range_, n);
                n = T.getBasis() * n;
            }
            if (d < best) {
                best = d;
                bestNormal = ei(n);
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
    std::vector<std::unique_ptr<SkinShape>> skins_;
    std::vector<std::unique_ptr<btCollisionObject>> objects_;
    float range_;
};

}  // namespace

CollisionWorld::CollisionWorld(const std::vector<ColliderShape>& shapes) : impl_(std::make_shared<Impl>()) {
    impl_->specs = shapes;
    for (const ColliderShape& s : shapes) impl_->shapes.push_back(makeShape(s));
}

CollisionWorld::~CollisionWorld() = default;

size_t CollisionWorld::size() const { return impl_->shapes.size(); }

std::shared_ptr<const Collider> CollisionWorld::posed(const std::vector<Eigen::Isometry3f>& poses, float range,
                                                      std::vector<std::vector<Vec3f>> skins) const {
    if (poses.size() != impl_->shapes.size())
        throw Error(cat("collision world: ", poses.size(), " poses for ", impl_->shapes.size(), " colliders"));
    return std::make_shared<PosedWorld>(impl_, poses, range, std::move(skins));
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
