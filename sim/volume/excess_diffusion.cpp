// Implicit diffusion of the density excess (equations: excess_diffusion.h).
#include "sim/volume/excess_diffusion.h"

#include <algorithm>
#include <utility>

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

void relaxExcess(const NodeBox& box, const float* e, const uint8_t* occupied, float c, int sweeps, float* out,
                 RelaxScratch& scratch, const ParallelFor& parallel) {
    const int nx = box.nx, ny = box.ny, nz = box.nz;
    const size_t n = box.size(), plane = size_t(nx) * size_t(ny);
    const float inv = 1.f / (1.f + 6.f * c);
    // Ping-pong between out and scratch so that the last sweep lands in out.
    scratch.values.resize(n);
    float* buf[2] = {out, scratch.values.data()};
    const int first = (sweeps % 2 == 1) ? 0 : 1;  // the buffer holding E^1
    // The first sweep from E⁰ = 0 is e/(1 + 6c) on the occupied nodes; the
    // other buffer starts at 0 (nodes without hair are never written again).
    // Occupied nodes are counted plane by plane for the list.
    scratch.planeStart.assign(size_t(nz) + 1, 0u);
    uint32_t* planeStart = scratch.planeStart.data();
    parallel(size_t(nz), [&](size_t b, size_t end) {
        for (size_t k = b; k < end; ++k) {
            uint32_t count = 0;
            for (size_t m = k * plane, last = m + plane; m < last; ++m) {
                buf[first][m] = occupied[m] ? e[m] * inv : 0.f;
                if (sweeps > 1) buf[1 - first][m] = 0.f;
                count += occupied[m] ? 1u : 0u;
            }
            planeStart[k + 1] = count;
        }
    });
    if (sweeps <= 1) return;
    for (int k = 0; k < nz; ++k) planeStart[k + 1] += planeStart[k];
    scratch.nodes.resize(planeStart[nz]);
    scratch.inside.resize(planeStart[nz]);
    uint32_t* nodes = scratch.nodes.data();
    uint8_t* inside = scratch.inside.data();
    parallel(size_t(nz), [&](size_t b, size_t end) {
        for (size_t k = b; k < end; ++k) {
            uint32_t t = planeStart[k];
            for (int j = 0; j < ny; ++j)
                for (int i = 0; i < nx; ++i) {
                    const size_t m = k * plane + size_t(j) * size_t(nx) + size_t(i);
                    if (!occupied[m]) continue;
                    nodes[t] = uint32_t(m);
                    inside[t++] = uint8_t(unsigned(i > 0) | unsigned(i + 1 < nx) << 1 | unsigned(j > 0) << 2 |
                                          unsigned(j + 1 < ny) << 3 | unsigned(k > 0) << 4 |
                                          unsigned(int(k) + 1 < nz) << 5);
                }
        }
    });
    // The sweeps of jacobiSweep on the listed nodes: the six neighbours in
    // the same order (x, y, z; minus, plus), those outside the box counting 0.
    int cur = first;
    for (int s = 1; s < sweeps; ++s) {
        const float* in = buf[cur];
        float* to = buf[1 - cur];
        parallel(size_t(nz), [&](size_t b, size_t end) {
            for (uint32_t t = planeStart[b]; t < planeStart[end]; ++t) {
                const size_t m = nodes[t];
                const unsigned f = inside[t];
                float sum = 0.f;
                if (f & 1u) sum += in[m - 1];
                if (f & 2u) sum += in[m + 1];
                if (f & 4u) sum += in[m - size_t(nx)];
                if (f & 8u) sum += in[m + size_t(nx)];
                if (f & 16u) sum += in[m - plane];
                if (f & 32u) sum += in[m + plane];
                to[m] = (e[m] + c * sum) * inv;
            }
        });
        cur = 1 - cur;
    }
}

}  // namespace hp::volume
