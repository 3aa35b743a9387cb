#include "render/image/colormap.h"

#include <algorithm>
#include <cmath>

namespace hp {

namespace {

struct Knot {
    float t, r, g, b;
};

// Entries 0, 16, 32, ..., 240, 255 of matplotlib's 256-entry magma table.
constexpr Knot kMagma[] = {
    {0.f / 255, 0.001462f, 0.000466f, 0.013866f},   {16.f / 255, 0.039608f, 0.031090f, 0.133515f},
    {32.f / 255, 0.113094f, 0.065492f, 0.276784f},  {48.f / 255, 0.211718f, 0.061992f, 0.418647f},
    {64.f / 255, 0.316654f, 0.071690f, 0.485380f},  {80.f / 255, 0.414709f, 0.110431f, 0.504662f},
    {96.f / 255, 0.512831f, 0.148179f, 0.507648f},  {112.f / 255, 0.613617f, 0.181811f, 0.498536f},
    {128.f / 255, 0.716387f, 0.214982f, 0.475290f}, {144.f / 255, 0.816914f, 0.255895f, 0.436461f},
    {160.f / 255, 0.904281f, 0.319610f, 0.388137f}, {176.f / 255, 0.960949f, 0.418323f, 0.359630f},
    {192.f / 255, 0.986700f, 0.535582f, 0.382210f}, {208.f / 255, 0.996096f, 0.653659f, 0.446213f},
    {224.f / 255, 0.996898f, 0.769591f, 0.534892f}, {240.f / 255, 0.992440f, 0.884330f, 0.640099f},
    {255.f / 255, 0.987053f, 0.991438f, 0.749504f},
};

}  // namespace

std::array<float, 3> magma(float t) {
    if (!(t > 0.f)) t = 0.f;  // also NaN
    t = std::min(t, 1.f);
    constexpr int n = int(sizeof kMagma / sizeof kMagma[0]);
    int i = 1;
    while (i < n - 1 && kMagma[i].t < t) ++i;
    const Knot& a = kMagma[i - 1];
    const Knot& b = kMagma[i];
    const float u = (t - a.t) / (b.t - a.t);
    return {a.r + u * (b.r - a.r), a.g + u * (b.g - a.g), a.b + u * (b.b - a.b)};
}

}  // namespace hp
