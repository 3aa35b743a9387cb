#include "sim/collision/mesh_query.h"

#include "core/errors.h"
#include "core/embree_ray.h"
#include "core/log.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <mutex>

namespace hp {

namespace {

/// One Embree device for the process: creating one per mesh would cost
/// milliseconds each. Embree's TBB build shares TBB's scheduler, so thread
/// limits (tbb::global_control) apply to its builds too.
RTCDevice device() {
    static RTCDevice d = [] {
        RTCDevice dev = rtcNewDevice("verbose=0");
        if (!dev) throw Error(cat("Embree: cannot create a device (error ", int(rtcGetDeviceError(nullptr)), ")"));
        rtcSetDeviceErrorFunction(
            dev, [](void*, RTCError code, const char* message) { logError("Embree error ", int(code), ": ", message); },
            nullptr);
        return dev;
    }();
    return d;
}

TrianglePoint vertexPoint(TriangleFeature f) {
    TrianglePoint r;
    r.feature = f;
    if (f == TriangleFeature::VertexB) r.b1 = 1.f;
    if (f == TriangleFeature::VertexC) r.b2 = 1.f;
    return r;
}

}  // namespace

float segmentParameter(const Vec3f& p, const Vec3f& p0, const Vec3f& p1) {
    const Vec3f d = p1 - p0;
    const float len2 = d.squaredNorm();
    return len2 > 0.f ? std::clamp((p - p0).dot(d) / len2, 0.f, 1.f) : 0.f;
}

TrianglePoint closestPointOnTriangle(const Vec3f& p, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
    const Vec3f ab = b - a, ac = c - a, ap = p - a;
    const float d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0.f && d2 <= 0.f) return vertexPoint(TriangleFeature::VertexA);
    const Vec3f bp = p - b;
    const float d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0.f && d4 <= d3) return vertexPoint(TriangleFeature::VertexB);
    const float vc = d1 * d4 - d3 * d2;
    if (vc <= 0.f && d1 >= 0.f && d3 <= 0.f) return {d1 / (d1 - d3), 0.f, TriangleFeature::EdgeAB};
    const Vec3f cp = p - c;
    const float d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0.f && d5 <= d6) return vertexPoint(TriangleFeature::VertexC);
    const float vb = d5 * d2 - d1 * d6;
    if (vb <= 0.f && d2 >= 0.f && d6 <= 0.f) return {0.f, d2 / (d2 - d6), TriangleFeature::EdgeCA};
    const float va = d3 * d6 - d5 * d4;
    if (va <= 0.f && (d4 - d3) >= 0.f && (d5 - d6) >= 0.f) {
        const float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return {1.f - w, w, TriangleFeature::EdgeBC};
    }
    const float sum = va + vb + vc;
    if (!(sum > 0.f) || !std::isfinite(1.f / sum)) {
        // Degenerate (zero-area) triangle: the best of its three edges.
        const float tab = segmentParameter(p, a, b), tbc = segmentParameter(p, b, c), tca = segmentParameter(p, c, a);
        const float eab = (a + tab * ab - p).squaredNorm();
        const float ebc = (b + tbc * (c - b) - p).squaredNorm();
        const float eca = (c + tca * (a - c) - p).squaredNorm();
        if (eab <= ebc && eab <= eca) return {tab, 0.f, TriangleFeature::EdgeAB};
        if (ebc <= eca) return {1.f - tbc, tbc, TriangleFeature::EdgeBC};
        return {0.f, 1.f - tca, TriangleFeature::EdgeCA};
    }
    const float inv = 1.f / sum;
    return {vb * inv, vc * inv, TriangleFeature::Face};
}

struct MeshQuery::Impl {
    RTCScene scene = nullptr;
    RTCGeometry geometry = nullptr;
    float* vertices = nullptr;         ///< Embree-owned, 3 floats per vertex (padded by Embree)
    size_t vertexCount = 0;
    std::vector<Tri> triangles;        ///< all triangles of the mesh
    std::vector<uint32_t> primToTri;   ///< BVH primitive -> mesh triangle

    Vec3f vertex(uint32_t i) const { return Vec3f(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]); }

    ~Impl() {
        if (geometry) rtcReleaseGeometry(geometry);
        if (scene) rtcReleaseScene(scene);
    }
};

namespace {

/// What the Embree callback needs (the Impl is private to MeshQuery).
struct PointQueryState {
    const float* vertices;
    const Tri* triangles;
    const uint32_t* primToTri;
    Vec3f p;
    MeshPoint best;
    float bestSq = std::numeric_limits<float>::infinity();
};

bool pointQueryCallback(RTCPointQueryFunctionArguments* args) {
    auto* s = static_cast<PointQueryState*>(args->userPtr);
    const uint32_t tri = s->primToTri[args->primID];
    const Tri& t = s->triangles[tri];
    auto vertex = [&](uint32_t i) { return Vec3f(s->vertices[3 * i], s->vertices[3 * i + 1], s->vertices[3 * i + 2]); };
    const Vec3f a = vertex(t[0]), b = vertex(t[1]), c = vertex(t[2]);
    const TrianglePoint tp = closestPointOnTriangle(s->p, a, b, c);
    const Vec3f q = (1.f - tp.b1 - tp.b2) * a + tp.b1 * b + tp.b2 * c;
    const float d2 = (q - s->p).squaredNorm();
    if (d2 < s->bestSq || (d2 == s->bestSq && tri < s->best.point.triangle)) {
        s->bestSq = d2;
        s->best.point = {tri, tp.b1, tp.b2};
        s->best.position = q;
        s->best.feature = tp.feature;
        // Shrink the search a hair beyond the distance, so triangles at the
        // same distance are still visited and the index tie-break decides.
        const float r = std::sqrt(d2) * (1.f + 1e-5f) + 1e-12f;
        if (r < args->query->radius) {
            args->query->radius = r;
            return true;
        }
    }
    return false;
}

}  // namespace

MeshQuery::MeshQuery(const TriangleMesh& mesh, const std::vector<uint8_t>& mask) : impl_(std::make_unique<Impl>()) {
    Impl& m = *impl_;
    if (!mask.empty() && mask.size() != mesh.triangles.size())
        throw Error(cat("MeshQuery: mask has ", mask.size(), " entries for ", mesh.triangles.size(), " triangles"));
    m.triangles = mesh.triangles;
    m.vertexCount = mesh.positions.size();
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
        if (mask.empty() || mask[t]) m.primToTri.push_back(t);

    m.scene = rtcNewScene(device());
    rtcSetSceneFlags(m.scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(m.scene, RTC_BUILD_QUALITY_MEDIUM);
    m.geometry = rtcNewGeometry(device(), RTC_GEOMETRY_TYPE_TRIANGLE);
    m.vertices = static_cast<float*>(rtcSetNewGeometryBuffer(m.geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                            3 * sizeof(float), std::max<size_t>(1, m.vertexCount)));
    for (size_t i = 0; i < m.vertexCount; ++i)
        for (int k = 0; k < 3; ++k) m.vertices[3 * i + k] = mesh.positions[i][k];
    if (!m.primToTri.empty()) {
        auto* index = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
            m.geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), m.primToTri.size()));
        for (size_t p = 0; p < m.primToTri.size(); ++p)
            for (int k = 0; k < 3; ++k) index[3 * p + k] = mesh.triangles[m.primToTri[p]][k];
        rtcCommitGeometry(m.geometry);
        rtcAttachGeometry(m.scene, m.geometry);
    }
    rtcCommitScene(m.scene);
    if (rtcGetDeviceError(device()) != RTC_ERROR_NONE) throw Error("Embree: building the mesh BVH failed");
}

MeshQuery::~MeshQuery() = default;

MeshPoint MeshQuery::closest(const Vec3f& p, float maxDistance) const {
    PointQueryState state{impl_->vertices, impl_->triangles.data(), impl_->primToTri.data(), p, {},
                          std::numeric_limits<float>::infinity()};
    if (impl_->primToTri.empty()) return state.best;
    RTCPointQuery query;
    query.x = p.x();
    query.y = p.y();
    query.z = p.z();
    query.time = 0.f;
    query.radius = maxDistance;
    RTCPointQueryContext context;
    rtcInitPointQueryContext(&context);
    rtcPointQuery(impl_->scene, &query, &context, pointQueryCallback, &state);
    if (state.bestSq <= maxDistance * maxDistance) state.best.distance = std::sqrt(state.bestSq);
    else state.best = MeshPoint{};
    return state.best;
}

RayHit MeshQuery::intersect(const Vec3f& origin, const Vec3f& direction, float tMin, float tMax) const {
    RayHit result;
    if (impl_->primToTri.empty()) return result;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh = embree::rayHit(origin, direction, tMin, tMax);
    rtcIntersect1(impl_->scene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return result;
    // Embree's (u, v) weight the second and third corner, as SurfacePoint does.
    result.point = {impl_->primToTri[rh.hit.primID], rh.hit.u, rh.hit.v};
    result.t = rh.ray.tfar;
    return result;
}

void MeshQuery::refit(const std::vector<Vec3f>& positions) {
    Impl& m = *impl_;
    if (positions.size() != m.vertexCount)
        throw Error(cat("MeshQuery::refit: ", positions.size(), " positions for ", m.vertexCount, " vertices"));
    for (size_t i = 0; i < m.vertexCount; ++i)
        for (int k = 0; k < 3; ++k) m.vertices[3 * i + k] = positions[i][k];
    rtcSetGeometryBuildQuality(m.geometry, RTC_BUILD_QUALITY_REFIT);
    if (m.primToTri.empty()) return;
    rtcUpdateGeometryBuffer(m.geometry, RTC_BUFFER_TYPE_VERTEX, 0);
    rtcCommitGeometry(m.geometry);
    rtcCommitScene(m.scene);
}

size_t MeshQuery::triangleCount() const { return impl_->primToTri.size(); }
Vec3f MeshQuery::vertex(uint32_t i) const { return impl_->vertex(i); }
const Tri& MeshQuery::triangle(uint32_t meshTriangle) const { return impl_->triangles[meshTriangle]; }

}  // namespace hp
