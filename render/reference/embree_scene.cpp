#include "render/reference/embree_scene.h"

#include "core/errors.h"
#include "core/embree_ray.h"
#include "core/log.h"

#include <embree3/rtcore.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

namespace hp {

// ---------------------------------------------------------------- device --

struct EmbreeDevice::Impl {
    RTCDevice device = nullptr;
    std::atomic<int64_t> bytes{0};
    std::atomic<int64_t> peak{0};
};

namespace {

bool memoryMonitor(void* user, ssize_t bytes, bool /*post*/) {
    // Each allocation is reported once (before or after it happens); we never
    // cancel, so every report is accumulated.
    auto* d = static_cast<EmbreeDevice::Impl*>(user);
    const int64_t now = d->bytes.fetch_add(int64_t(bytes)) + int64_t(bytes);
    int64_t peak = d->peak.load();
    while (now > peak && !d->peak.compare_exchange_weak(peak, now)) {
    }
    return true;
}

void embreeError(void* /*user*/, RTCError code, const char* message) {
    if (code != RTC_ERROR_NONE) logWarning("embree: ", message ? message : "unknown error", " (code ", int(code), ")");
}

}  // namespace

EmbreeDevice::EmbreeDevice() : impl_(std::make_unique<Impl>()) {
    impl_->device = rtcNewDevice(nullptr);
    if (!impl_->device) throw Error(cat("cannot create an Embree device (error ", int(rtcGetDeviceError(nullptr)), ")"));
    rtcSetDeviceErrorFunction(impl_->device, embreeError, nullptr);
    rtcSetDeviceMemoryMonitorFunction(impl_->device, memoryMonitor, impl_.get());
}

EmbreeDevice::~EmbreeDevice() { rtcReleaseDevice(impl_->device); }

int64_t EmbreeDevice::bytesInUse() const { return impl_->bytes.load(); }
int64_t EmbreeDevice::peakBytes() const { return impl_->peak.load(); }
void EmbreeDevice::resetPeak() { impl_->peak.store(impl_->bytes.load()); }

// ----------------------------------------------------------------- scene --

struct EmbreeScene::Impl {
    RTCScene scene = nullptr;
    unsigned hairGeom = RTC_INVALID_GEOMETRY_ID;
    unsigned headGeom = RTC_INVALID_GEOMETRY_ID;
    const float* controlPoints = nullptr;  // Embree-owned (x, y, z, r), lives with the scene
    const uint32_t* segmentStart = nullptr;
    std::vector<uint32_t> segmentStrand;    // strand of each segment
    std::vector<uint32_t> ids;              // stable id of each strand
    std::vector<Vec3f> headNormals;
    std::vector<Tri> headTriangles;
    size_t strands = 0;
};

namespace {

/// Hits on the query's own strand within one segment of its start are the
/// fibre's own surface.
bool ownSurface(const EmbreeScene::Impl& s, const RayStart& start, unsigned prim) {
    // A strand's segments are consecutive primitives: compare indices first
    // and touch the (large, cache-cold) strand table only for neighbours.
    if (start.strand == kNoStrand || prim + 1 < start.segment || prim > start.segment + 1) return false;
    return s.segmentStrand[prim] == start.strand;
}

struct IntersectQuery {
    RTCIntersectContext context;  // first member: Embree hands this pointer back to the filter
    const EmbreeScene::Impl* scene;
    RayStart start;
};

void skipOwnSurface(const RTCFilterFunctionNArguments* args) {
    const auto* q = reinterpret_cast<const IntersectQuery*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        if (RTCHitN_geomID(args->hit, args->N, i) != q->scene->hairGeom) {
            if (q->start.throughHead) args->valid[i] = 0;  // as shadow rays: a ray from the head ignores it
            continue;
        }
        if (ownSurface(*q->scene, q->start, RTCHitN_primID(args->hit, args->N, i))) args->valid[i] = 0;
    }
}

constexpr int kMaxRecorded = 256;

struct ShadowQuery {
    RTCIntersectContext context;
    const EmbreeScene::Impl* scene;
    RayStart start;
    int maxCrossings;  // this many crossings leave less than 1e-4 of the light: stop
    int crossings = 0;
    int recorded = 0;
    uint32_t strand[kMaxRecorded];
    uint32_t segment[kMaxRecorded];
};

void accumulateShadow(const RTCFilterFunctionNArguments* args) {
    auto* q = reinterpret_cast<ShadowQuery*>(args->context);
    const EmbreeScene::Impl& s = *q->scene;
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] != -1) continue;
        if (RTCHitN_geomID(args->hit, args->N, i) != s.hairGeom) {
            if (q->start.throughHead) args->valid[i] = 0;  // a ray from the head ignores it
            continue;                                      // otherwise the head is opaque: accept
        }
        const unsigned prim = RTCHitN_primID(args->hit, args->N, i);
        if (ownSurface(s, q->start, prim)) {
            args->valid[i] = 0;
            continue;
        }
        if (q->maxCrossings <= 0) continue;  // opaque hair: accept
        const uint32_t strand = s.segmentStrand[prim];
        bool seen = false;
        for (int r = 0; r < q->recorded && !seen; ++r)
            seen = q->strand[r] == strand && prim + 1 >= q->segment[r] && prim <= q->segment[r] + 1;
        if (seen) {
            args->valid[i] = 0;
            continue;
        }
        if (q->recorded < kMaxRecorded) {
            q->strand[q->recorded] = strand;
            q->segment[q->recorded] = prim;
            ++q->recorded;
        }
        if (++q->crossings < q->maxCrossings) args->valid[i] = 0;  // continue through this strand
    }
}

void checkEmbree(RTCDevice device, const char* what) {
    const RTCError e = rtcGetDeviceError(device);
    if (e != RTC_ERROR_NONE) throw FrameError(cat("Embree failed to ", what, " (error ", int(e), ")"));
}

bool finite(const Vec3f& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

void validateStrands(const StrandFrame& f) {
    if (f.offsets.empty() || f.offsets.front() != 0 || f.offsets.back() != f.positions.size())
        throw FrameError(cat("strands: offsets do not cover the ", f.positions.size(), " vertices"));
    if (f.radii.size() != f.positions.size())
        throw FrameError(cat("strands: ", f.radii.size(), " radii for ", f.positions.size(), " vertices"));
    for (size_t s = 0; s < f.strandCount(); ++s) {
        if (f.offsets[s + 1] < f.offsets[s]) throw FrameError(cat("strands: offsets decrease at strand ", s));
        for (uint32_t k = f.offsets[s]; k < f.offsets[s + 1]; ++k) {
            const uint32_t id = s < f.ids.size() ? f.ids[s] : uint32_t(s);
            if (!finite(f.positions[k]))
                throw FrameError(cat("strand ", s, " (id ", id, ") vertex ", k - f.offsets[s], ": position is not finite (",
                                     f.positions[k].x(), ", ", f.positions[k].y(), ", ", f.positions[k].z(), ")"));
            if (!std::isfinite(f.radii[k]) || f.radii[k] < 0.f)
                throw FrameError(cat("strand ", s, " (id ", id, ") vertex ", k - f.offsets[s], ": radius ", f.radii[k],
                                     " is not a finite non-negative number"));
        }
    }
}

}  // namespace

EmbreeScene::EmbreeScene(const EmbreeDevice& device, const StrandFrame* strands, const TriangleMesh* head)
    : impl_(std::make_unique<Impl>()) {
    RTCDevice dev = device.impl().device;
    Impl& s = *impl_;
    s.scene = rtcNewScene(dev);
    // Compact: half the memory (372 → 201 MB at 100k strands), no slower to
    // trace here. Context filters: own-surface skipping and shadow
    // transmittance, set per query.
    rtcSetSceneFlags(s.scene, RTCSceneFlags(RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION | RTC_SCENE_FLAG_COMPACT));
    rtcSetSceneBuildQuality(s.scene, RTC_BUILD_QUALITY_MEDIUM);

    if (strands && strands->strandCount() > 0) {
        validateStrands(*strands);
        const StrandFrame& f = *strands;
        s.strands = f.strandCount();
        size_t segments = 0, points = 0;
        for (size_t i = 0; i < f.strandCount(); ++i) {
            const uint32_t n = f.vertexCount(i);
            if (n < 2) continue;  // a single point is no curve
            segments += n - 1;
            points += n + 2;
        }
        s.ids.resize(f.strandCount());
        for (size_t i = 0; i < f.strandCount(); ++i) s.ids[i] = i < f.ids.size() ? f.ids[i] : uint32_t(i);
        if (segments > 0) {
            RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_ROUND_CATMULL_ROM_CURVE);
            auto* cp = static_cast<float*>(
                rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), points));
            auto* index = static_cast<uint32_t*>(
                rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(uint32_t), segments));
            if (!cp || !index) {
                rtcReleaseGeometry(g);
                checkEmbree(dev, "allocate the strand buffers");
                throw FrameError("Embree failed to allocate the strand buffers");
            }
            s.segmentStrand.resize(segments);
            size_t p = 0, seg = 0;
            auto put = [&](const Vec3f& x, float r) {
                cp[4 * p + 0] = x.x(), cp[4 * p + 1] = x.y(), cp[4 * p + 2] = x.z(), cp[4 * p + 3] = r;
                ++p;
            };
            for (size_t i = 0; i < f.strandCount(); ++i) {
                const uint32_t n = f.vertexCount(i), first = f.first(i);
                if (n < 2) continue;
                const Vec3f* x = &f.positions[first];
                const float* r = &f.radii[first];
                const size_t base = p;
                put(2.f * x[0] - x[1], r[0]);  // phantom before the root
                for (uint32_t k = 0; k < n; ++k) put(x[k], r[k]);
                put(2.f * x[n - 1] - x[n - 2], r[n - 1]);  // phantom after the tip
                for (uint32_t k = 0; k + 1 < n; ++k) {
                    index[seg] = uint32_t(base + k);
                    s.segmentStrand[seg] = uint32_t(i);
                    ++seg;
                }
            }
            rtcCommitGeometry(g);
            s.hairGeom = rtcAttachGeometry(s.scene, g);
            rtcReleaseGeometry(g);  // the scene keeps it (and its buffers) alive
            s.controlPoints = cp;
            s.segmentStart = index;
        }
    }

    if (head && !head->triangles.empty()) {
        const TriangleMesh& m = *head;
        for (size_t v = 0; v < m.positions.size(); ++v)
            if (!finite(m.positions[v])) throw FrameError(cat("head mesh vertex ", v, ": position is not finite"));
        for (size_t t = 0; t < m.triangles.size(); ++t)
            for (uint32_t c : m.triangles[t])
                if (c >= m.positions.size())
                    throw FrameError(cat("head mesh triangle ", t, ": vertex index ", c, " out of range (",
                                         m.positions.size(), " vertices)"));
        RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                              3 * sizeof(float), m.positions.size()));
        auto* t = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                 3 * sizeof(uint32_t), m.triangles.size()));
        if (!v || !t) {
            rtcReleaseGeometry(g);
            throw FrameError("Embree failed to allocate the head buffers");
        }
        for (size_t i = 0; i < m.positions.size(); ++i)
            v[3 * i] = m.positions[i].x(), v[3 * i + 1] = m.positions[i].y(), v[3 * i + 2] = m.positions[i].z();
        for (size_t i = 0; i < m.triangles.size(); ++i)
            for (int c = 0; c < 3; ++c) t[3 * i + c] = m.triangles[i][c];
        rtcCommitGeometry(g);
        s.headGeom = rtcAttachGeometry(s.scene, g);
        rtcReleaseGeometry(g);
        s.headTriangles = m.triangles;
        if (m.normals.size() == m.positions.size()) {
            s.headNormals = m.normals;
        } else {
            TriangleMesh copy = m;
            copy.computeNormals();
            s.headNormals = copy.normals;
        }
    }

    rtcCommitScene(s.scene);
    checkEmbree(dev, "build the scene");
}

EmbreeScene::~EmbreeScene() { rtcReleaseScene(impl_->scene); }

SceneHit EmbreeScene::intersect(const Vec3f& o, const Vec3f& d, float tnear, float tfar, const RayStart& start) const {
    IntersectQuery q;
    rtcInitIntersectContext(&q.context);
    q.scene = impl_.get();
    q.start = start;
    if (start.strand != kNoStrand || start.throughHead) q.context.filter = skipOwnSurface;

    RTCRayHit rh = embree::rayHit(o, d, tnear, tfar);
    rtcIntersect1(impl_->scene, &q.context, &rh);

    SceneHit hit;
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return hit;
    hit.t = rh.ray.tfar;
    Vec3f ng(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
    const float len = ng.norm();
    hit.ng = len > 0.f ? Vec3f(ng / len) : Vec3f(-d);
    if (rh.hit.geomID == impl_->hairGeom) {
        hit.kind = SceneHit::Kind::Hair;
        hit.segment = rh.hit.primID;
        hit.strand = impl_->segmentStrand[rh.hit.primID];
        hit.u = rh.hit.u;
    } else {
        hit.kind = SceneHit::Kind::Head;
        hit.triangle = rh.hit.primID;
        hit.b1 = rh.hit.u;
        hit.b2 = rh.hit.v;
    }
    return hit;
}

float EmbreeScene::transmittance(const Vec3f& o, const Vec3f& d, float tnear, float tfar, float hairTransmittance,
                                 const RayStart& start) const {
    ShadowQuery q;
    rtcInitIntersectContext(&q.context);
    q.context.filter = accumulateShadow;
    q.scene = impl_.get();
    q.start = start;
    if (hairTransmittance <= 0.f) q.maxCrossings = 0;
    else if (hairTransmittance >= 1.f) q.maxCrossings = std::numeric_limits<int>::max();
    else q.maxCrossings = std::max(1, int(std::ceil(std::log(1e-4f) / std::log(hairTransmittance))));

    RTCRay ray = embree::ray(o, d, tnear, tfar);
    rtcOccluded1(impl_->scene, &q.context, &ray);
    if (ray.tfar < 0.f) return 0.f;  // an accepted hit: the head, opaque hair, or too many crossings
    return q.crossings == 0 ? 1.f : std::pow(hairTransmittance, float(q.crossings));
}

CurvePoint EmbreeScene::curvePoint(uint32_t segment, float u) const {
    // Uniform Catmull-Rom: p(u) = ½ [(−u³+2u²−u) p0 + (3u³−5u²+2) p1 + (−3u³+4u²+u) p2 + (u³−u²) p3].
    const float* c = impl_->controlPoints + 4 * size_t(impl_->segmentStart[segment]);
    const float u2 = u * u, u3 = u2 * u;
    const float b[4] = {0.5f * (-u3 + 2.f * u2 - u), 0.5f * (3.f * u3 - 5.f * u2 + 2.f),
                        0.5f * (-3.f * u3 + 4.f * u2 + u), 0.5f * (u3 - u2)};
    const float db[4] = {0.5f * (-3.f * u2 + 4.f * u - 1.f), 0.5f * (9.f * u2 - 10.f * u),
                         0.5f * (-9.f * u2 + 8.f * u + 1.f), 0.5f * (3.f * u2 - 2.f * u)};
    CurvePoint out;
    Vec3f dp = Vec3f::Zero();
    for (int k = 0; k < 4; ++k) {
        const Vec3f p(c[4 * k], c[4 * k + 1], c[4 * k + 2]);
        out.position += b[k] * p;
        out.radius += b[k] * c[4 * k + 3];
        dp += db[k] * p;
    }
    if (dp.squaredNorm() < 1e-20f) dp = Vec3f(c[8] - c[4], c[9] - c[5], c[10] - c[6]);
    const float len = dp.norm();
    out.tangent = len > 0.f ? Vec3f(dp / len) : Vec3f::UnitX();
    return out;
}

Vec3f EmbreeScene::headShadingNormal(uint32_t triangle, float b1, float b2) const {
    const Tri& t = impl_->headTriangles[triangle];
    const auto& n = impl_->headNormals;
    const Vec3f v = (1.f - b1 - b2) * n[t[0]] + b1 * n[t[1]] + b2 * n[t[2]];
    const float len = v.norm();
    return len > 0.f ? Vec3f(v / len) : Vec3f::UnitY();
}

size_t EmbreeScene::strandCount() const { return impl_->strands; }
size_t EmbreeScene::segmentCount() const { return impl_->segmentStrand.size(); }
uint32_t EmbreeScene::strandId(uint32_t strand) const {
    return strand < impl_->ids.size() ? impl_->ids[strand] : strand;
}

}  // namespace hp
