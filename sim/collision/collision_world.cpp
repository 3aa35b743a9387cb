#include "sim/collision/collision_world.h"

#include "core/errors.h"
#include "sim/collision/bullet_adapter.h"

#include <btBulletCollisionCommon.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpa2.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>

#include <limits>
#include <mutex>

namespace hp {

namespace {

using bullet::bt;
using bullet::ei;

/// Margin of boxes and hulls: GJK treats a shape as its core grown by the
/// margin (rounded edges of this radius), so keep it far below hair scale.
constexpr float kMargin = 1e-4f;

void checkTriangles(const ColliderShape& s) {
    if (s.triangles.empty()) throw Error("collision world: a triangle mesh collider needs triangles");
    for (const Tri& t : s.triangles)
        for (uint32_t i : t)
            if (i >= s.points.size()) throw Error("collision world: a triangle names a vertex the mesh lacks");
}

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
        case ColliderShape::Kind::Mesh:
        case ColliderShape::Kind::SkinnedMesh:
            checkTriangles(s);
            return nullptr;  // a PropShape (Mesh), or a SkinShape per pose
    }
    throw Error("collision world: unknown shape");
}

/// A triangle mesh Bullet reads in place: its vertices, indices and the
/// btTriangleIndexVertexArray over them.
struct TriangleArrays {
    std::vector<Vec3f> vertices;
    std::vector<int> indices;
    std::unique_ptr<btTriangleIndexVertexArray> array;

    TriangleArrays(std::vector<Vec3f> v, const std::vector<Tri>& triangles) : vertices(std::move(v)) {
        for (const Tri& t : triangles)
            for (uint32_t i : t) indices.push_back(int(i));
        static_assert(sizeof(Vec3f) == 3 * sizeof(btScalar), "Bullet reads the vertices in place");
        array = std::make_unique<btTriangleIndexVertexArray>(int(triangles.size()), indices.data(), 3 * int(sizeof(int)),
                                                             int(vertices.size()),
                                                             reinterpret_cast<btScalar*>(vertices.data()->data()),
                                                             int(sizeof(Vec3f)));
    }
};

/// A rigid prop as Bullet's GImpact mesh: the triangles themselves (a hat's
/// inside stays open, where a hull would fill it), over a box-set BVH built
/// once. Queries read the box set and the locked triangle data only
/// (btGImpactQuantizedBvh::boxQuery, getPrimitiveTriangle), which is safe
/// from many threads; GImpact's own processAllTriangles locks and unlocks
/// the mesh per call and is not.
struct PropShape {
    TriangleArrays mesh;
    std::unique_ptr<btGImpactMeshShape> shape;

    explicit PropShape(const ColliderShape& s) : mesh(s.points, s.triangles) {
        shape = std::make_unique<btGImpactMeshShape>(mesh.array.get());
        shape->setMargin(kMargin);
        shape->updateBound();
        shape->getMeshPart(0)->lockChildShapes();  // held for the shape's life: queries only read
    }
    ~PropShape() { shape->getMeshPart(0)->unlockChildShapes(); }
};

/// A skinned mesh's tree: its own copy of the vertices, Bullet's view of
/// them and a quantized BVH built once on the rest pose. Each pose copies
/// its vertices in and refits the tree (btBvhTriangleMeshShape::refitTree:
/// the node boxes are recomputed bottom-up, the topology kept), which costs
/// a pass over the triangles instead of a build. A body bends smoothly, so
/// the rest pose's tree stays a good one.
struct SkinShape {
    TriangleArrays mesh;
    std::unique_ptr<btBvhTriangleMeshShape> shape;

    explicit SkinShape(const ColliderShape& s) : mesh(s.points, s.triangles) {
        shape = std::make_unique<btBvhTriangleMeshShape>(mesh.array.get(), true);
    }

    /// Moves the skin to `pose` (as many vertices as the rest pose) and refits the tree.
    void refit(const std::vector<Vec3f>& pose) {
        if (pose.size() != mesh.vertices.size())
            throw Error(cat("collision world: a skinned mesh pose has ", pose.size(), " vertices, its rest pose ",
                            mesh.vertices.size()));
        std::copy(pose.begin(), pose.end(), mesh.vertices.begin());  // in place: Bullet holds the pointer
        Eigen::AlignedBox3f box;
        for (const Vec3f& p : pose) box.extend(p);
        // The quantization range must hold every vertex; a margin keeps
        // the outermost boxes from rounding onto the surface.
        const Vec3f pad = Vec3f::Constant(1e-3f + 1e-4f * box.sizes().maxCoeff());
        shape->refitTree(bt(Vec3f(box.min() - pad)), bt(Vec3f(box.max() + pad)));
    }
};

}  // namespace

struct CollisionWorld::Impl {
    std::vector<ColliderShape> specs;
    std::vector<std::unique_ptr<btCollisionShape>> shapes;  ///< primitives and hulls; null for triangle meshes
    std::vector<std::unique_ptr<PropShape>> props;          ///< per collider: the GImpact mesh of a rigid prop
    // Shared by every posed world. Only queries run there, never a
    // dispatch, so no collision algorithm is ever created or freed in them.
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher{&config};

    /// Skinned trees not in use, per collider (refitted by the next pose).
    std::mutex poolMutex;
    std::vector<std::vector<std::unique_ptr<SkinShape>>> pool;

    std::unique_ptr<SkinShape> borrow(size_t i) {
        {
            std::lock_guard<std::mutex> lock(poolMutex);
            if (!pool[i].empty()) {
                std::unique_ptr<SkinShape> s = std::move(pool[i].back());
                pool[i].pop_back();
                return s;
            }
        }
        return std::make_unique<SkinShape>(specs[i]);  // a build, once per tree alive at a time
    }
    void giveBack(size_t i, std::unique_ptr<SkinShape> s) {
        std::lock_guard<std::mutex> lock(poolMutex);
        pool[i].push_back(std::move(s));
    }
};

namespace {

/// Signed distance from `q` (mesh coordinates) to the nearest triangle of a
/// mesh within `range`, fed the candidate triangles by the mesh's BVH:
/// Bullet's closest point on each; inside when q lies behind the nearest
/// triangle's face. At an edge or a corner several triangles are nearest:
/// the one q lies most squarely above or below (largest |n·(q - c)| /
/// |q - c|) decides the sign.
struct Nearest final : btTriangleCallback {
    btVector3 q;
    float distance;        ///< unsigned, of the nearest triangle so far
    float square = -1.f;   ///< |n·(q - c)| / |q - c| of that triangle
    bool inside = false;
    btVector3 normal{0, 1, 0};
    /// Only its stateless closest-point routine is used: one per query, not
    /// per triangle (it is a large object to construct).
    btVoronoiSimplexSolver solver;

    Nearest(const btVector3& point, float range) : q(point), distance(range) {}

    void processTriangle(btVector3* t, int, int) override {
        btVector3 n = (t[1] - t[0]).cross(t[2] - t[0]);
        if (n.length2() <= 0) return;
        n.normalize();
        // Bullet's exact Voronoi-region closest point on a triangle (GJK
        // on a flat triangle stops ~10% short of it in float).
        btSubSimplexClosestResult closest;
        solver.closestPtPointTriangle(q, t[0], t[1], t[2], closest);
        const btVector3 e = q - closest.m_closestPointOnSimplex;
        const float len = float(e.length()), h = float(n.dot(e));
        const float sq = len > 1e-9f ? std::abs(h) / len : 1.f;
        if (len < distance - 1e-7f || (len < distance + 1e-7f && sq > square)) {
            distance = len;
            square = sq;
            inside = h < 0.f;
            normal = len > 1e-9f ? (inside ? -e / len : e / len) : n;
        }
    }

    /// The signed distance, and the normal to push along.
    float result(btVector3& n) const {
        n = normal;
        return inside ? -distance : distance;
    }
};

/// Counts the triangles a ray from `from` along `dir` crosses (Möller and
/// Trumbore's ray-triangle test): odd means `from` is inside a closed mesh.
struct Crossings final : btTriangleCallback {
    btVector3 from, dir;
    int count = 0;
    Crossings(const btVector3& f, const btVector3& d) : from(f), dir(d) {}
    void processTriangle(btVector3* t, int, int) override {
        const btVector3 e1 = t[1] - t[0], e2 = t[2] - t[0], p = dir.cross(e2);
        const btScalar det = e1.dot(p);
        if (std::abs(det) < 1e-12f) return;  // parallel to the ray
        const btVector3 s = from - t[0];
        const btScalar u = s.dot(p) / det;
        if (u < 0 || u > 1) return;
        const btVector3 qv = s.cross(e1);
        const btScalar v = dir.dot(qv) / det;
        if (v < 0 || u + v > 1) return;
        count += e2.dot(qv) / det > 0;
    }
};

/// A ray direction no mesh edge of ours lines up with (an axis would graze
/// the seams of a mesh built on a grid).
const btVector3 kRayDirection = btVector3(0.5377f, 0.6411f, -0.5476f).normalized();

/// The nearest triangle within `range`, asking `visit(nearest, box
/// half-width)` for the triangles in ever larger boxes about q: a box of
/// half-width r holds every triangle within r, so the search stops at the
/// first box whose nearest triangle is within its half-width. Hair lies
/// within millimetres of a surface, where the first, small box holds a
/// few triangles instead of the hundreds of the full range. With none
/// within range, q is clear unless `inside()` (ray parity) says it lies
/// deep inside the mesh; then the boxes grow on until they find the way
/// out, so a vertex pushed deep into a body still gets its exact depth.
template <typename Visit, typename Inside>
float nearestTriangle(const btVector3& q, float range, btVector3& normal, Visit&& visit, Inside&& inside) {
    bool deep = false;
    for (float r = range / 16.f;; r = deep ? 4.f * r : std::min(range, 4.f * r)) {
        Nearest nearest(q, r);
        visit(nearest, btVector3(r, r, r));
        if (nearest.distance < r || r > 1e3f) return nearest.result(normal);
        if (r >= range && !deep) {
            if (!inside()) return nearest.result(normal);
            deep = true;
        }
    }
}

/// The length of a ray from q that surely leaves a shape's local box.
float rayLength(const btCollisionShape& shape, const btVector3& q) {
    btVector3 lo, hi;
    shape.getAabb(btTransform::getIdentity(), lo, hi);
    return float((hi - lo).length() + 2 * (q - 0.5f * (lo + hi)).length()) + 1.f;
}

/// A skinned mesh: its refitted BVH lists the triangles near q.
float meshDistance(const btBvhTriangleMeshShape& mesh, const btVector3& q, float range, btVector3& normal) {
    return nearestTriangle(
        q, range, normal,
        [&](Nearest& nearest, const btVector3& r) { mesh.processAllTriangles(&nearest, q - r, q + r); },
        [&] {
            Crossings crossings(q, kRayDirection);
            // A read-only walk of the tree, as processAllTriangles is.
            const_cast<btBvhTriangleMeshShape&>(mesh).performRaycast(&crossings, q,
                                                                     q + rayLength(mesh, q) * kRayDirection);
            return crossings.count % 2 == 1;
        });
}

/// A rigid prop: its GImpact box set lists the triangles near q.
float meshDistance(const btGImpactMeshShape& mesh, const btVector3& q, float range, btVector3& normal) {
    const btGImpactMeshShapePart& part = *mesh.getMeshPart(0);
    auto visitAll = [&](btTriangleCallback& callback, const btAlignedObjectArray<int>& near) {
        btPrimitiveTriangle t;
        for (int k = 0; k < near.size(); ++k) {
            part.getPrimitiveTriangle(near[k], t);
            callback.processTriangle(t.m_vertices, 0, near[k]);
        }
    };
    return nearestTriangle(
        q, range, normal,
        [&](Nearest& nearest, const btVector3& r) {
            btAABB box;
            box.m_min = q - r;
            box.m_max = q + r;
            btAlignedObjectArray<int> near;
            part.getBoxSet()->boxQuery(box, near);
            visitAll(nearest, near);
        },
        [&] {
            Crossings crossings(q, kRayDirection);
            btAlignedObjectArray<int> along;
            part.getBoxSet()->rayQuery(kRayDirection, q, along);
            visitAll(crossings, along);
            return crossings.count % 2 == 1;
        });
}

/// A posed world: one collision object per shape, one broadphase.
class PosedWorld final : public Collider {
  public:
    PosedWorld(std::shared_ptr<CollisionWorld::Impl> impl, const std::vector<Eigen::Isometry3f>& poses, float range,
               const std::vector<std::vector<Vec3f>>& skins)
        : impl_(std::move(impl)), world_(&impl_->dispatcher, &broadphase_, &impl_->config), range_(range) {
        const size_t n = impl_->specs.size();
        // The skins first, so a bad pose throws before any object is in the world.
        skins_.resize(n);
        try {
            for (size_t i = 0; i < n; ++i) {
                if (impl_->specs[i].kind != ColliderShape::Kind::SkinnedMesh) continue;
                if (i >= skins.size() || skins[i].empty())
                    throw Error(cat("collision world: no vertices for skinned collider ", i));
                skins_[i] = impl_->borrow(i);
                skins_[i]->refit(skins[i]);
            }
        } catch (...) {
            giveBack();
            throw;
        }
        objects_.reserve(n);
        for (size_t i = 0; i < n; ++i) {
            auto o = std::make_unique<btCollisionObject>();
            o->setCollisionShape(impl_->shapes[i]  ? impl_->shapes[i].get()
                                 : impl_->props[i] ? static_cast<btCollisionShape*>(impl_->props[i]->shape.get())
                                                   : skins_[i]->shape.get());
            o->setWorldTransform(bt(poses[i]));
            o->setUserIndex(int(i));
            world_.addCollisionObject(o.get());
            objects_.push_back(std::move(o));
        }
        world_.updateAabbs();
    }
    ~PosedWorld() override {
        for (auto& o : objects_) world_.removeCollisionObject(o.get());
        giveBack();
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
                const btVector3 local = T.invXform(q);
                d = shape->getShapeType() == GIMPACT_SHAPE_PROXYTYPE
                        ? meshDistance(*static_cast<const btGImpactMeshShape*>(shape), local, range_, n)
                        : meshDistance(*static_cast<const btBvhTriangleMeshShape*>(shape), local, range_, n);
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
    void giveBack() {
        for (size_t i = 0; i < skins_.size(); ++i)
            if (skins_[i]) impl_->giveBack(i, std::move(skins_[i]));
    }

    std::shared_ptr<CollisionWorld::Impl> impl_;  // the shapes outlive this world
    btDbvtBroadphase broadphase_;
    btCollisionWorld world_;
    std::vector<std::unique_ptr<SkinShape>> skins_;  ///< per collider: the refitted tree this pose borrows
    std::vector<std::unique_ptr<btCollisionObject>> objects_;
    float range_;
};

}  // namespace

CollisionWorld::CollisionWorld(const std::vector<ColliderShape>& shapes) : impl_(std::make_shared<Impl>()) {
    impl_->specs = shapes;
    impl_->pool.resize(shapes.size());
    for (size_t i = 0; i < shapes.size(); ++i) {
        impl_->shapes.push_back(makeShape(shapes[i]));
        impl_->props.push_back(shapes[i].kind == ColliderShape::Kind::Mesh ? std::make_unique<PropShape>(shapes[i])
                                                                            : nullptr);
        // Build the first tree now, so a bad skin fails here and the first pose only refits.
        if (shapes[i].kind == ColliderShape::Kind::SkinnedMesh)
            impl_->pool[i].push_back(std::make_unique<SkinShape>(shapes[i]));
    }
}

CollisionWorld::~CollisionWorld() = default;

size_t CollisionWorld::size() const { return impl_->shapes.size(); }

std::shared_ptr<const Collider> CollisionWorld::posed(const std::vector<Eigen::Isometry3f>& poses, float range,
                                                      std::vector<std::vector<Vec3f>> skins) const {
    if (poses.size() != impl_->shapes.size())
        throw Error(cat("collision world: ", poses.size(), " poses for ", impl_->shapes.size(), " colliders"));
    return std::make_shared<PosedWorld>(impl_, poses, range, skins);
}

float CompositeCollider::signedDistance(const Vec3f& p, Vec3f* normal) const {
    return signedDistanceIgnoring(p, normal, 0u);
}

float CompositeCollider::signedDistanceIgnoring(const Vec3f& p, Vec3f* normal, uint32_t ignoreParts) const {
    float best = std::numeric_limits<float>::infinity();
    if (head_) best = ignoreParts ? head_->signedDistanceIgnoring(p, normal, ignoreParts) : head_->signedDistance(p, normal);
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
