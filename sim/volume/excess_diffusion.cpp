// Implicit diffusion of the density excess (equations: excess_diffusion.h).
#include "sim/volume/excess_diffusion.h"

#include <algorithm>
#include <cstring>
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

void OccupiedNodes::reset(const NodeBox& b) {
    box = b;
    const size_t n = b.size();
    if (node.size() < n) {
        node.resize(n);
        inside.resize(n);
        excess.resize(n);
    }
    count.assign(size_t(b.nz), 0u);
}

void relaxListed(OccupiedNodes& list, float c, int sweeps, float* out, const ParallelFor& parallel) {
    const NodeBox& box = list.box;
    const size_t n = box.size(), plane = size_t(box.nx) * size_t(box.ny), nx = size_t(box.nx);
    const float inv = 1.f / (1.f + 6.f * c);
    // Ping-pong between out and values so that the last sweep lands in out;
    // both start at 0, and nodes not listed are never written again.
    list.values.resize(n);
    float* buf[2] = {out, list.values.data()};
    std::memset(out, 0, n * sizeof(float));
    if (sweeps > 1) std::memset(buf[1], 0, n * sizeof(float));
    int cur = (sweeps % 2 == 1) ? 0 : 1;  // the buffer holding E^1
    const uint32_t* node = list.node.data();
    const uint8_t* inside = list.inside.data();
    const float* e = list.excess.data();
    const uint32_t* count = list.count.data();
    // The first sweep from E⁰ = 0 is e/(1 + 6c) on the listed nodes.
    parallel(size_t(box.nz), [&](size_t b, size_t end) {
        for (size_t k = b; k < end; ++k)
            for (size_t t = k * plane, last = t + count[k]; t < last; ++t) buf[cur][node[t]] = e[t] * inv;
    });
    // jacobiSweep on the listed nodes: the six neighbours in the same order
    // (x, y, z; minus, plus), those outside the box counting 0.
    for (int s = 1; s < sweeps; ++s) {
        const float* in = buf[cur];
        float* to = buf[1 - cur];
        parallel(size_t(box.nz), [&](size_t b, size_t end) {
            for (size_t k = b; k < end; ++k)
                for (size_t t = k * plane, last = t + count[k]; t < last; ++t) {
                    const size_t m = node[t];
                    const unsigned f = inside[t];
                    float sum = 0.f;
                    if (f & 1u) sum += in[m - 1];
                    if (f & 2u) sum += in[m + 1];
                    if (f & 4u) sum += in[m - nx];
                    if (f & 8u) sum += in[m + nx];
                    if (f & 16u) sum += in[m - plane];
                    if (f & 32u) sum += in[m + plane];
                    to[m] = (e[t] + c * sum) * inv;
                }
        });
        cur = 1 - cur;
    }
}

void relaxExcess(const NodeBox& box, const float* e, const uint8_t* occupied, float c, int sweeps, float* out,
                 OccupiedNodes& scratch, const ParallelFor& parallel) {
    scratch.reset(box);
    for (int k = 0; k < box.nz; ++k)
        for (int j = 0; j < box.ny; ++j)
            for (int i = 0; i < box.nx; ++i) {
                const size_t m = (size_t(k) * size_t(box.ny) + size_t(j)) * size_t(box.nx) + size_t(i);
                if (occupied[m]) scratch.add(i, j, k, e[m]);
            }
    relaxListed(scratch, c, sweeps, out, parallel);
}

}  // namespace hp::volume
