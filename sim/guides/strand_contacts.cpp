// Strand-strand collision for the rope formulation (Gomes 2024, Table 5.1 row 7): every
// segment is a Bullet capsule in one btCollisionWorld; Bullet's dynamic AABB
// tree finds the overlapping pairs and its capsule-capsule narrowphase the
// closest points, and the contacts are resolved at position level in a fixed
// order. It couples all guides, so it runs serially between the parallel
// per-world steps (that is its cost; the switch is off by default).
#include "sim/collision/bullet_adapter.h"
#include "sim/collision/mesh_query.h"
#include "sim/guides/guide_group.h"
#include "sim/guides/segment_contact.h"

#include <btBulletCollisionCommon.h>

#include <algorithm>
#include <map>
#include <tuple>

namespace hp::guides {
namespace {

using bullet::bt;
using bullet::ei;

/// Rejects pairs of one guide's neighbouring segments (they share a vertex).
struct NeighbourFilter final : btOverlapFilterCallback {
    bool needBroadphaseCollision(btBroadphaseProxy* a, btBroadphaseProxy* b) const override {
        const auto* oa = static_cast<const btCollisionObject*>(a->m_clientObject);
        const auto* ob = static_cast<const btCollisionObject*>(b->m_clientObject);
        if (oa->getUserIndex() != ob->getUserIndex()) return true;
        return std::abs(oa->getUserIndex2() - ob->getUserIndex2()) > 1;
    }
};

struct SegmentContact {
    uint32_t guideA, segA, guideB, segB;
    float s, t;
    Vec3f normal;  ///< from B to A
};

/// The capsule of segment (a, b): centred, local Y along the segment.
btTransform capsuleTransform(const Vec3f& a, const Vec3f& b) {
    const Vec3f d = b - a;
    const float len = d.norm();
    const strand::Quatf q =
        len > 0.f ? strand::Quatf::FromTwoVectors(Vec3f::UnitY(), d / len) : strand::Quatf::Identity();
    btTransform t;
    t.setOrigin(bt(0.5f * (a + b)));
    t.setRotation(bt(q));
    return t;
}


}  // namespace

struct StrandContacts::Impl {
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher{&config};
    std::unique_ptr<bt32BitAxisSweep3> broadphase;
    std::unique_ptr<btCollisionWorld> world;
    Eigen::Isometry3f toLocal = Eigen::Isometry3f::Identity();  // world -> head-local at this substep
    NeighbourFilter filter;
    std::map<float, std::unique_ptr<btCapsuleShape>> shapes;  // one per distinct rest length
    std::vector<std::unique_ptr<btCollisionObject>> objects;  // guide-major, segment-minor
    std::vector<SegmentContact> contacts;
    std::vector<Vec3f> before;

    ~Impl() {
        for (auto& o : objects) world->removeCollisionObject(o.get());
    }
};

void useHairScaleContactThreshold() {
    // Bullet widens every box by this global (2 cm by default, for metre-sized
    // bodies); around 1 cm segments it pairs each capsule with dozens of
    // neighbours (measured: 94 guides at 2 steps/s and 0.8 GB). Hair needs
    // millimetres. Only ever lowered, before any world steps.
    gContactBreakingThreshold = std::min(gContactBreakingThreshold, btScalar(0.002));
}

StrandContacts::StrandContacts(const GuideSet& set) : impl_(std::make_unique<Impl>()) {
    useHairScaleContactThreshold();
    Impl& m = *impl_;
    // Sweep-and-prune in head-local coordinates. Bullet's dynamic AABB tree
    // pads every leaf by a fixed 5 cm (DBVT_BP_MARGIN), which pairs each 1 cm
    // capsule with hundreds of others (measured: 250k pairs for 94 guides);
    // SAP pairs exact boxes but needs bounds, and hair always stays within
    // its length of the scalp, which is fixed in head coordinates.
    m.toLocal = set.headTransform.inverse();
    Eigen::AlignedBox3f box;
    float longest = 0.f;
    for (size_t g = 0; g < set.count; ++g) {
        float len = 0.f;
        for (int j = 0; j < set.segments; ++j) len += set.restLength[set.segment(g, j)];
        longest = std::max(longest, len);
        box.extend(m.toLocal * set.x[set.vertex(g, 0)]);
    }
    const Vec3f pad = Vec3f::Constant(1.5f * longest + 0.01f);
    m.broadphase = std::make_unique<bt32BitAxisSweep3>(bt(box.min() - pad), bt(box.max() + pad),
                                                       unsigned(set.count * set.segments + 16), nullptr, true);
    m.broadphase->getOverlappingPairCache()->setOverlapFilterCallback(&m.filter);
    m.world = std::make_unique<btCollisionWorld>(&m.dispatcher, m.broadphase.get(), &m.config);
    const float r = set.settings.collisionRadius;
    for (size_t g = 0; g < set.count; ++g)
        for (int j = 0; j < set.segments; ++j) {
            const float len = set.restLength[set.segment(g, j)];
            auto& shape = m.shapes[len];
            if (!shape) shape = std::make_unique<btCapsuleShape>(r, std::max(len - 2.f * r, 0.f));
            auto obj = std::make_unique<btCollisionObject>();
            obj->setCollisionShape(shape.get());
            obj->setUserIndex(int(g));
            obj->setUserIndex2(j);
            // Posed before insertion: objects all at the origin would pair up
            // every capsule with every other, and Bullet only prunes stale
            // pairs a tenth at a time.
            obj->setWorldTransform(capsuleTransform(m.toLocal * set.x[set.vertex(g, j)],
                                                    m.toLocal * set.x[set.vertex(g, j + 1)]));
            m.world->addCollisionObject(obj.get());
            m.objects.push_back(std::move(obj));
        }
}

StrandContacts::~StrandContacts() = default;

size_t StrandContacts::solve(GuideSet& set, float h, const std::function<void(size_t)>& relax) {
    Impl& m = *impl_;
    const float r = set.settings.collisionRadius;
    // Capsules along the current segments, in head-local coordinates.
    m.toLocal = set.headTransform.inverse();
    const Mat3f toWorld = set.headTransform.linear();
    for (size_t g = 0; g < set.count; ++g)
        for (int j = 0; j < set.segments; ++j)
            m.objects[g * set.segments + j]->setWorldTransform(
                capsuleTransform(m.toLocal * set.x[set.vertex(g, j)], m.toLocal * set.x[set.vertex(g, j + 1)]));
    m.world->performDiscreteCollisionDetection();

    // One contact per touching pair (its deepest point), in canonical order.
    m.contacts.clear();
    for (int i = 0; i < m.dispatcher.getNumManifolds(); ++i) {
        const btPersistentManifold* pm = m.dispatcher.getManifoldByIndexInternal(i);
        int best = -1;
        for (int p = 0; p < pm->getNumContacts(); ++p)
            if (pm->getContactPoint(p).getDistance() < 0.f &&
                (best < 0 || pm->getContactPoint(p).getDistance() < pm->getContactPoint(best).getDistance()))
                best = p;
        if (best < 0) continue;
        const btManifoldPoint& pt = pm->getContactPoint(best);
        const auto* oa = pm->getBody0();
        const auto* ob = pm->getBody1();
        SegmentContact c;
        c.guideA = uint32_t(oa->getUserIndex());
        c.segA = uint32_t(oa->getUserIndex2());
        c.guideB = uint32_t(ob->getUserIndex());
        c.segB = uint32_t(ob->getUserIndex2());
        c.normal = toWorld * ei(pt.m_normalWorldOnB);
        const Vec3f pa = m.toLocal.inverse() * ei(pt.getPositionWorldOnA());
        const Vec3f pb = m.toLocal.inverse() * ei(pt.getPositionWorldOnB());
        c.s = segmentParameter(pa, set.x[set.vertex(c.guideA, c.segA)], set.x[set.vertex(c.guideA, c.segA + 1)]);
        c.t = segmentParameter(pb, set.x[set.vertex(c.guideB, c.segB)], set.x[set.vertex(c.guideB, c.segB + 1)]);
        if (std::tie(c.guideB, c.segB) < std::tie(c.guideA, c.segA)) {
            std::swap(c.guideA, c.guideB);
            std::swap(c.segA, c.segB);
            std::swap(c.s, c.t);
            c.normal = -c.normal;
        }
        m.contacts.push_back(c);
    }
    std::sort(m.contacts.begin(), m.contacts.end(), [](const SegmentContact& a, const SegmentContact& b) {
        return std::tie(a.guideA, a.segA, a.guideB, a.segB) < std::tie(b.guideA, b.segA, b.guideB, b.segB);
    });

    // Gauss-Seidel over the contacts, each re-measured on the current
    // positions so shared vertices are not pushed twice.
    m.before = set.x;
    std::vector<size_t> touched;
    const float mu = set.settings.friction;
    for (const SegmentContact& c : m.contacts) {
        const size_t ia = set.vertex(c.guideA, c.segA), ib = set.vertex(c.guideB, c.segB);
        Vec3f &a0 = set.x[ia], &a1 = set.x[ia + 1], &b0 = set.x[ib], &b1 = set.x[ib + 1];
        const Vec3f pa = a0 + c.s * (a1 - a0), pb = b0 + c.t * (b1 - b0);
        const float depth = 2.f * r - (pa - pb).dot(c.normal);
        if (depth <= 0.f) continue;
        const float w[4] = {set.mass[ia] > 0 ? 1.f / set.mass[ia] : 0.f, 1.f / set.mass[ia + 1],
                            set.mass[ib] > 0 ? 1.f / set.mass[ib] : 0.f, 1.f / set.mass[ib + 1]};
        strand::separateSegments(a0, a1, b0, b1, c.s, c.t, c.normal, depth, w);
        // Coulomb friction on the relative sliding velocity, bounded by μ times
        // the normal velocity the push implies (depth / h), split by weights.
        Vec3f &va0 = set.v[ia], &va1 = set.v[ia + 1], &vb0 = set.v[ib], &vb1 = set.v[ib + 1];
        const Vec3f rel = (va0 + c.s * (va1 - va0)) - (vb0 + c.t * (vb1 - vb0));
        Vec3f vt = rel - rel.dot(c.normal) * c.normal;
        const float vtLen = vt.norm();
        if (vtLen > 0.f) {
            const float k = std::min(1.f, mu * depth / h / vtLen) * 0.5f;
            va0 -= k * (1.f - c.s) * vt * (w[0] > 0 ? 1.f : 0.f);
            va1 -= k * c.s * vt;
            vb0 += k * (1.f - c.t) * vt * (w[2] > 0 ? 1.f : 0.f);
            vb1 += k * c.t * vt;
        }
        touched.push_back(c.guideA);
        touched.push_back(c.guideB);
    }
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    for (size_t g : touched) relax(g);
    // The pushes become velocity (position-based dynamics).
    for (size_t g : touched)
        for (int i = 1; i < set.vertices; ++i) {
            const size_t k = set.vertex(g, i);
            set.v[k] += (set.x[k] - m.before[k]) / h;
        }
    return m.contacts.size();
}

}  // namespace hp::guides
