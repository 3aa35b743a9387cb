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

void OccupiedNodes::reset(size_t planes, const uint32_t* start, size_t valueCount, uint32_t zeroSlot) {
    const size_t room = start[planes];
    if (node.size() < room) {
        node.resize(room);
        neighbour.resize(room);
        excess.resize(room);
    }
    first.assign(start, start + planes);
    count.assign(planes, 0u);
    values = valueCount;
    zero = zeroSlot;
}

void relaxListed(OccupiedNodes& list, float c, int sweeps, float* out, const ParallelFor& parallel) {
    const size_t n = list.values, planes = list.first.size();
    const float inv = 1.f / (1.f + 6.f * c);
    // Ping-pong between out and scratch so that the last sweep lands in
    // out; both start at 0, and slots not listed are never written again.
    list.scratch.resize(n);
    float* buf[2] = {out, list.scratch.data()};
    if (planes == 0) std::memset(out, 0, n * sizeof(float));  // the zero slot alone
    parallel(planes, [&](size_t b, size_t end) {  // cleared in chunks on the threads
        const size_t from = n * b / planes, to = n * end / planes;
        std::memset(out + from, 0, (to - from) * sizeof(float));
        if (sweeps > 1) std::memset(buf[1] + from, 0, (to - from) * sizeof(float));
    });
    int cur = (sweeps % 2 == 1) ? 0 : 1;  // the buffer holding E^1
    const uint32_t* node = list.node.data();
    const std::array<uint32_t, 6>* around = list.neighbour.data();
    const float* e = list.excess.data();
    const uint32_t* first = list.first.data();
    const uint32_t* count = list.count.data();
    // The first sweep from E⁰ = 0 is e/(1 + 6c) on the listed nodes.
    parallel(planes, [&](size_t b, size_t end) {
        for (size_t k = b; k < end; ++k)
            for (size_t t = first[k], last = t + count[k]; t < last; ++t) buf[cur][node[t]] = e[t] * inv;
    });
    // jacobiSweep on the listed nodes: the six neighbours in the same order
    // (x, y, z; minus, plus), those outside the zero slot.
    for (int s = 1; s < sweeps; ++s) {
        const float* in = buf[cur];
        float* to = buf[1 - cur];
        parallel(planes, [&](size_t b, size_t end) {
            for (size_t k = b; k < end; ++k)
                for (size_t t = first[k], last = t + count[k]; t < last; ++t) {
                    const std::array<uint32_t, 6>& a = around[t];
                    float sum = 0.f;
                    sum += in[a[0]];
                    sum += in[a[1]];
                    sum += in[a[2]];
                    sum += in[a[3]];
                    sum += in[a[4]];
                    sum += in[a[5]];
                    to[node[t]] = (e[t] + c * sum) * inv;
                }
        });
        cur = 1 - cur;
    }
}

void relaxExcess(const NodeBox& box, const float* e, const uint8_t* occupied, float c, int sweeps, float* out,
                 OccupiedNodes& scratch, const ParallelFor& parallel) {
    // Value slots: the box's nodes, then the zero slot.
    const size_t plane = size_t(box.nx) * size_t(box.ny), size = box.size();
    const uint32_t zero = uint32_t(size);
    std::vector<uint32_t> start(size_t(box.nz) + 1);
    for (size_t k = 0; k <= size_t(box.nz); ++k) start[k] = uint32_t(k * plane);
    scratch.reset(size_t(box.nz), start.data(), size + 1, zero);
    for (int k = 0; k < box.nz; ++k)
        for (int j = 0; j < box.ny; ++j)
            for (int i = 0; i < box.nx; ++i) {
                const uint32_t m = uint32_t((size_t(k) * size_t(box.ny) + size_t(j)) * size_t(box.nx) + size_t(i));
                if (!occupied[m]) continue;
                const uint32_t nx = uint32_t(box.nx), pl = uint32_t(plane);
                scratch.add(size_t(k), m,
                            {i > 0 ? m - 1 : zero, i + 1 < box.nx ? m + 1 : zero, j > 0 ? m - nx : zero,
                             j + 1 < box.ny ? m + nx : zero, k > 0 ? m - pl : zero, k + 1 < box.nz ? m + pl : zero},
                            e[m]);
            }
    std::vector<float> values(size + 1);
    relaxListed(scratch, c, sweeps, values.data(), parallel);
    std::copy(values.begin(), values.begin() + std::ptrdiff_t(size), out);
}

}  // namespace hp::volume
