#include "sim/curly/wet_forces.h"

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

// ---- SpatialGrid -----------------------------------------------------------------

void SpatialGrid::build(const Vec3f* points, const uint32_t* groups, size_t count, float radius) {
    Eigen::AlignedBox3f box;
    for (size_t i = 0; i < count; ++i)
        if (points[i].allFinite()) box.extend(points[i]);
    if (box.isEmpty()) box.extend(Vec3f::Zero());
    origin_ = box.min();
    const Vec3f extent = box.sizes();
    float cell = radius;
    auto dims = [&](float c) {
        nx_ = int64_t(extent.x() / c) + 1;
        ny_ = int64_t(extent.y() / c) + 1;
        nz_ = int64_t(extent.z() / c) + 1;
        return double(nx_) * double(ny_) * double(nz_);
    };
    const double budget = 4.0 * double(count) + 64.0;
    for (double cells = dims(cell); cells > budget; cells = dims(cell)) cell *= float(std::cbrt(cells / budget)) * 1.01f;
    inv_ = 1.f / cell;
    const size_t cells = size_t(nx_ * ny_ * nz_);
    start_.assign(cells + 1, 0);
    entries_.resize(count);
    std::vector<uint32_t> cellOf(count);
    for (size_t i = 0; i < count; ++i) {
        size_t c = 0;  // non-finite points go to cell 0, where distance tests reject them
        if (points[i].allFinite()) {
            const Vec3f p = (points[i] - origin_) * inv_;
            const int64_t x = std::min<int64_t>(int64_t(p.x()), nx_ - 1), y = std::min<int64_t>(int64_t(p.y()), ny_ - 1),
                          z = std::min<int64_t>(int64_t(p.z()), nz_ - 1);
            c = size_t((z * ny_ + y) * nx_ + x);
        }
        cellOf[i] = uint32_t(c);
        ++start_[c + 1];
    }
    for (size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
    std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < count; ++i) entries_[fill[cellOf[i]]++] = Entry{points[i], uint32_t(i), groups[i]};
}

// ---- Cohesion --------------------------------------------------------------------

float poly6(float r2, float h) {
    const float h2 = h * h;
    if (r2 >= h2) return 0.f;
    const float d = h2 - r2;
    return float(315.0 / (64.0 * M_PI)) / std::pow(h, 9.f) * d * d * d;
}

void cohesionTargets(const SpatialGrid& grid, const float* sigma, size_t begin, size_t end, float radius,
                     float tightness, CohesionTarget* out) {
    // poly6 without its constant, which cancels in the normalised average.
    const float r2max = radius * radius;
    const float w0 = r2max * r2max * r2max;
    for (size_t k = begin; k < end; ++k) {
        const Vec3f& x = grid.orderedPoint(k);
        const uint32_t own = grid.orderedGroup(k);
        Vec3f sum = Vec3f::Zero();
        float wSum = 0.f, wSigma = 0.f;
        uint32_t count = 0;
        grid.forEachNear(x, [&](uint32_t j, const Vec3f& pj, uint32_t strand) {
            if (strand == own) return;
            const Vec3f d = pj - x;
            const float r2 = d.squaredNorm();
            if (!(r2 < r2max)) return;
            const float q = r2max - r2;
            const float w = q * q * q;
            sum += sigma[j] * w * d;
            wSigma += sigma[j] * w;
            wSum += w;
            ++count;
        });
        CohesionTarget& t = out[grid.ordered(k)];
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
