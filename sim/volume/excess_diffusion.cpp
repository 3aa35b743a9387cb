// Implicit diffusion of the density excess (equations: excess_diffusion.h).
#include "sim/volume/excess_diffusion.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <utility>

#include <emmintrin.h>

namespace hp::volume {

void jacobiSweep(const NodeBox& box, const float* e, const uint8_t* occupied, float c, const float* in, float* out,
                 int k0, int k1) {
    const int nx = box.nx, ny = box.ny, nz = box.nz;
    const size_t plane = size_t(nx) * size_t(ny);
    const float inv = 1.f / (1.f + 6.f * c);
    for (int k = k0; k < k1; ++k)
        for (int j = 0; j < ny; ++j) {
            const size_t row = size_t(k) * plane + size_t(j) * size_t(nx);
            for (int i = 0; i < nx; ++i) {
                const size_t n = row + size_t(i);
                if (!occupied[n]) {
                    out[n] = 0.f;
                    continue;
                }
                // The six neighbours in a fixed order (x, y, z; minus, plus).
                float sum = 0.f;
                if (i > 0) sum += in[n - 1];
                if (i + 1 < nx) sum += in[n + 1];
                if (j > 0) sum += in[n - size_t(nx)];
                if (j + 1 < ny) sum += in[n + size_t(nx)];
                if (k > 0) sum += in[n - plane];
                if (k + 1 < nz) sum += in[n + plane];
                out[n] = (e[n] + c * sum) * inv;
            }
        }
}

namespace {

/// A neighbour row's values as seen from a row: value(i) = src[off + i] for
/// i in [vlo, vend) (its nodes and its two zero slots), 0 beyond. A row
/// that holds nothing reads a row of zeros over the whole lattice.
struct NearRow {
    const float* src;
    ptrdiff_t off;
    int vlo, vend;
    float at(int i) const { return i >= vlo && i < vend ? src[off + i] : 0.f; }
};

}  // namespace

void sweepRows(const NodeRows& rows, const float* ex, float c, const float* in, float* out, int k0, int k1) {
    const int ny = rows.ny, nz = rows.nz;
    const float inv = 1.f / (1.f + 6.f * c);
    const __m128 c4 = _mm_set1_ps(c), inv4 = _mm_set1_ps(inv), zero = _mm_setzero_ps();
    const std::vector<float> zeros(size_t(rows.nx) + 2, 0.f);  // value(i) = zeros[1 + i], i in [−1, nx]
    for (int k = k0; k < k1; ++k)
        for (int j = 0; j < ny; ++j) {
            const size_t r = size_t(k) * size_t(ny) + size_t(j);
            const int lo = rows.lo[r], end = rows.end[r];
            if (lo >= end) continue;
            const ptrdiff_t base = rows.base[r];
            out[base + lo - 1] = 0.f;  // the zero slots
            out[base + end] = 0.f;
            // Rows y−, y+, z−, z+; one outside the lattice or empty reads 0.
            const bool has[4] = {j > 0, j + 1 < ny, k > 0, k + 1 < nz};
            const size_t near[4] = {r - 1, r + 1, r - size_t(ny), r + size_t(ny)};
            NearRow nb[4];
            int ilo = lo, iend = end;  // the nodes whose four neighbour rows all hold a slot at i
            for (int a = 0; a < 4; ++a) {
                const size_t m = near[a];
                if (has[a] && rows.lo[m] < rows.end[m]) {
                    nb[a] = {in, rows.base[m], rows.lo[m] - 1, rows.end[m] + 1};
                } else {
                    nb[a] = {zeros.data(), 1, -1, rows.nx + 1};
                }
                ilo = std::max(ilo, nb[a].vlo);
                iend = std::min(iend, nb[a].vend);
            }
            if (iend < ilo) iend = ilo;
            auto node = [&](int i) {  // jacobiSweep's operations, one node
                const ptrdiff_t q = base + i;
                if (ex[q] != ex[q]) {  // NaN: no hair
                    out[q] = 0.f;
                    return;
                }
                float sum = 0.f;
                sum += in[q - 1];
                sum += in[q + 1];
                sum += nb[0].at(i);
                sum += nb[1].at(i);
                sum += nb[2].at(i);
                sum += nb[3].at(i);
                out[q] = (ex[q] + c * sum) * inv;
            };
            int i = lo;
            for (; i < ilo; ++i) node(i);
            // All four neighbour rows hold slots here: four nodes at a time.
            for (; i + 4 <= iend; i += 4) {
                const ptrdiff_t q = base + i;
                __m128 sum = _mm_add_ps(zero, _mm_loadu_ps(in + q - 1));
                sum = _mm_add_ps(sum, _mm_loadu_ps(in + q + 1));
                for (int a = 0; a < 4; ++a) sum = _mm_add_ps(sum, _mm_loadu_ps(nb[a].src + nb[a].off + i));
                const __m128 e = _mm_loadu_ps(ex + q);
                const __m128 E = _mm_mul_ps(_mm_add_ps(e, _mm_mul_ps(c4, sum)), inv4);
                _mm_storeu_ps(out + q, _mm_and_ps(_mm_cmpord_ps(e, e), E));
            }
            for (; i < end; ++i) node(i);
        }
}

const float* relaxRows(const NodeRows& rows, const float* ex, float c, int sweeps, int e0, int e1, float* a,
                       float* b, const ParallelFor& parallel) {
    if (sweeps <= 1 || e0 >= e1) return a;  // E¹, or no excess: E¹ = 0 everywhere
    const int nz = rows.nz;
    auto planes = [&](int s, int& k0, int& k1) {  // the planes sweep s reaches
        k0 = std::max(0, e0 - (s - 1));
        k1 = std::min(nz, e1 + (s - 1));
    };
    // Sweep 2 into b, which also clears b's other planes: later sweeps
    // into b reach further and read their neighbours there as 0 (a's
    // planes beyond the excess hold E¹ = 0 already).
    int k0, k1;
    planes(2, k0, k1);
    parallel(size_t(nz), [&](size_t pb, size_t pe) {
        for (size_t k = pb; k < pe; ++k) {
            if (int(k) >= k0 && int(k) < k1) {
                sweepRows(rows, ex, c, a, b, int(k), int(k) + 1);
            } else {
                const uint32_t from = rows.planeStart[k], to = rows.planeStart[k + 1];
                std::memset(b + from, 0, (to - from) * sizeof(float));
            }
        }
    });
    float* in = b;
    float* out = a;
    for (int s = 3; s <= sweeps; ++s) {
        planes(s, k0, k1);
        parallel(size_t(k1 - k0), [&](size_t pb, size_t pe) {
            sweepRows(rows, ex, c, in, out, k0 + int(pb), k0 + int(pe));
        });
        std::swap(in, out);
    }
    return in;  // the last sweep's buffer
}

void relaxExcess(const NodeBox& box, const float* e, const uint8_t* occupied, float c, int sweeps, float* out,
                 const ParallelFor& parallel) {
    // Every row stored whole, with its two zero slots.
    const int nx = box.nx, ny = box.ny, nz = box.nz;
    const size_t rowsCount = size_t(ny) * size_t(nz), stride = size_t(nx) + 2;
    std::vector<ptrdiff_t> base(rowsCount);
    std::vector<int> lo(rowsCount, 0), end(rowsCount, nx);
    std::vector<uint32_t> planeStart(size_t(nz) + 1);
    for (size_t r = 0; r < rowsCount; ++r) base[r] = ptrdiff_t(r * stride + 1);
    for (size_t k = 0; k <= size_t(nz); ++k) planeStart[k] = uint32_t(k * size_t(ny) * stride);
    NodeRows rows;
    rows.nx = nx;
    rows.ny = ny;
    rows.nz = nz;
    rows.base = base.data();
    rows.lo = lo.data();
    rows.end = end.data();
    rows.planeStart = planeStart.data();
    const size_t slots = rowsCount * stride;
    const float inv = 1.f / (1.f + 6.f * c);
    std::vector<float> ex(slots, std::numeric_limits<float>::quiet_NaN()), a(slots), b(slots);
    int e0 = nz, e1 = 0;
    for (size_t n = 0; n < box.size(); ++n) {
        const size_t r = n / size_t(nx), i = n % size_t(nx);
        if (!occupied[n]) continue;
        ex[size_t(base[r]) + i] = e[n];
        if (e[n] != 0.f) {
            e0 = std::min(e0, int(r / size_t(ny)));
            e1 = std::max(e1, int(r / size_t(ny)) + 1);
        }
    }
    for (size_t q = 0; q < slots; ++q) a[q] = firstSweep(ex[q], inv);
    const float* E = relaxRows(rows, ex.data(), c, sweeps, e0, e1, a.data(), b.data(), parallel);
    for (size_t n = 0; n < box.size(); ++n) out[n] = E[size_t(base[n / size_t(nx)]) + n % size_t(nx)];
}

}  // namespace hp::volume
