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
                 std::vector<float>& scratch, const ParallelFor& parallel) {
    const size_t n = box.size();
    // The first sweep from E⁰ = 0 is e/(1 + 6c) on the occupied nodes.
    const float inv = 1.f / (1.f + 6.f * c);
    // Ping-pong between out and scratch so that the last sweep lands in out.
    scratch.resize(n);
    float* buf[2] = {out, scratch.data()};
    int cur = (sweeps % 2 == 1) ? 0 : 1;  // the buffer holding E^1
    parallel(size_t(box.nz), [&](size_t b, size_t end) {
        for (size_t k = b; k < end; ++k) {
            const size_t first = k * size_t(box.nx) * size_t(box.ny), last = first + size_t(box.nx) * size_t(box.ny);
            for (size_t m = first; m < last; ++m) buf[cur][m] = occupied[m] ? e[m] * inv : 0.f;
        }
    });
    for (int s = 1; s < sweeps; ++s) {
        const float* in = buf[cur];
        float* to = buf[1 - cur];
        parallel(size_t(box.nz), [&](size_t b, size_t end) { jacobiSweep(box, e, occupied, c, in, to, int(b), int(end)); });
        cur = 1 - cur;
    }
}

}  // namespace hp::volume
