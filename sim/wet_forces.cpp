#include "sim/wet_forces.h"

#include <algorithm>
#include <cmath>

namespace hp::curly {

float saturationAt(float scene, float root, float tip, float s) {
    return std::clamp(scene * ((1.f - s) * root + s * tip), 0.f, 1.f);
}

namespace {
Mat3f cross(const Vec3f& g) {
    Mat3f m;
    m << 0.f, -g.z(), g.y(), g.z(), 0.f, -g.x(), -g.y(), g.x(), 0.f;
    return m;
}
}  // namespace

Mat3f alignRotation(const Vec3f& from, const Vec3f& to) {
    const Vec3f g = from.cross(to);
    const float c = from.dot(to);
    const float g2 = g.squaredNorm();
    if (g2 < 1e-12f) {
        if (c > 0.f) return Mat3f::Identity();
        // Half turn about any axis perpendicular to `from`: R = 2aaᵀ - I.
        const Vec3f a = from.unitOrthogonal();
        return 2.f * a * a.transpose() - Mat3f::Identity();
    }
    const Mat3f psi = cross(g);
    return Mat3f::Identity() + psi + psi * psi * ((1.f - c) / g2);
}

void curlForces(const Vec3f* p, size_t n, const Vec3f* helix, const Mat3f& root, const float* sigma, float weight,
                Vec3f* force) {
    if (n < 2) return;
    const Vec3f hDir = (root * (helix[n - 1] - helix[0])).normalized();
    const Vec3f chord = p[n - 1] - p[0];
    const float len = chord.norm();
    const Vec3f pDir = len > 1e-12f ? Vec3f(chord / len) : hDir;
    const Mat3f M = alignRotation(hDir, pDir) * root;
    for (size_t i = 0; i + 1 < n; ++i) {
        const float ws = 0.5f * (sigma[i] + sigma[i + 1]);
        force[i] = (M * (helix[i + 1] - helix[i])) * (weight * ws);
    }
}

// ---- SpatialHash ---------------------------------------------------------------

uint64_t SpatialHash::key(int64_t i, int64_t j, int64_t k) {
    // 21 bits per axis: ±10⁶ cells, ±10 km at a 1 cm cell.
    const uint64_t m = (1ull << 21) - 1;
    return (uint64_t(i) & m) | ((uint64_t(j) & m) << 21) | ((uint64_t(k) & m) << 42);
}

uint32_t SpatialHash::bucket(uint64_t c) const {
    // A 64-bit mix (splitmix64's finaliser) folded onto the table.
    c ^= c >> 31;
    c *= 0x7fb5d329728ea185ull;
    c ^= c >> 27;
    return uint32_t(c & mask_);
}

void SpatialHash::build(const Vec3f* points, const uint32_t* groups, size_t count, float radius) {
    inv_ = 1.f / radius;
    size_t table = 1;  // a power of two ≥ 2·count: buckets by mask, not division
    while (table < 2 * count) table *= 2;
    mask_ = table - 1;
    start_.assign(table + 1, 0);
    entries_.resize(count);
    std::vector<uint64_t> cellOf(count);
    std::vector<uint32_t> bucketOf(count);
    for (size_t i = 0; i < count; ++i) {
        const Vec3f& x = points[i];
        cellOf[i] = key(int64_t(std::floor(x.x() * inv_)), int64_t(std::floor(x.y() * inv_)),
                        int64_t(std::floor(x.z() * inv_)));
        bucketOf[i] = bucket(cellOf[i]);
        ++start_[bucketOf[i] + 1];
    }
    for (size_t b = 0; b < table; ++b) start_[b + 1] += start_[b];
    std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < count; ++i) entries_[fill[bucketOf[i]]++] = Entry{cellOf[i], points[i], uint32_t(i), groups[i]};
}

// ---- Cohesion --------------------------------------------------------------------

float poly6(float r2, float h) {
    const float h2 = h * h;
    if (r2 >= h2) return 0.f;
    const float d = h2 - r2;
    return float(315.0 / (64.0 * M_PI)) / std::pow(h, 9.f) * d * d * d;
}

void cohesionTargets(const SpatialHash& hash, const Vec3f* points, const float* sigma, const uint32_t* strandOf,
                     size_t begin, size_t end, float radius, float tightness, CohesionTarget* out) {
    // poly6 without its constant, which cancels in the normalised average.
    const float r2max = radius * radius;
    const float w0 = r2max * r2max * r2max;
    for (size_t i = begin; i < end; ++i) {
        const Vec3f& x = points[i];
        Vec3f sum = Vec3f::Zero();
        float wSum = 0.f, wSigma = 0.f;
        uint32_t count = 0;
        const uint32_t own = strandOf[i];
        hash.forEachNear(x, [&](uint32_t j, const Vec3f& pj, uint32_t strand) {
            if (strand == own) return;
            const Vec3f d = pj - x;
            const float r2 = d.squaredNorm();
            if (r2 >= r2max) return;
            const float q = r2max - r2;
            const float w = q * q * q;
            sum += sigma[j] * w * d;
            wSigma += sigma[j] * w;
            wSum += w;
            ++count;
        });
        CohesionTarget& t = out[i - begin];
        const float norm = tightness / (w0 + wSum);
        t.offset = sum * norm;
        t.weight = wSigma * norm;
        t.neighbours = count;
    }
}

// ---- Adhesion -------------------------------------------------------------------

float adhesionKernel(float r, float h) {
    if (!(r > 0.5f * h) || r > h) return 0.f;
    return 0.007f / std::pow(h, 3.25f) * (-4.f * r * r / h + 6.f * r - 2.f * h);
}

Vec3f adhesionAcceleration(float phi, const Vec3f& normal, float sigma, float nu, float radius) {
    if (!(sigma > 0.f) || !(phi > 0.f) || phi > radius) return Vec3f::Zero();
    return -(sigma * nu * adhesionKernel(100.f * phi, 100.f * radius)) * normal;
}

float wetVelocityFactor(float sigma, float gamma0, float gamma1) { return sigma * gamma0 + (1.f - sigma) * gamma1; }

}  // namespace hp::curly
