// The test oracle for Kajiya-Kay shading, written from the equations of Dehlin and Styngberg 2017
// and not from render/view/view.cpp, so the renderers' shading is checked against
// the paper rather than against itself:
//   diffuse  = kd · sin(t, l) · colour
//   specular = ks · sin(t', h)^α · specular colour,  h = (l + v)/|l + v|,
// where sin(a, b) = |a × b| for unit vectors, and t' is the tangent tilted
// along the view-facing normal n by the lobe's shift (Scheuermann's two-lobe
// variant: t' = (t + shift·n)/|t + shift·n|; shift 0 is Dehlin and Styngberg 2017's single
// lobe). A second lobe, when on, adds its own ks, exponent, shift and colour.
#pragma once

#include "render/view/view.h"

#include <cmath>

namespace hp::test {

/// Radiance leaving a hair point per unit incident radiance (RGB).
inline Vec3f seedKajiyaKay(const HairMaterial& m, const Vec3f& t, const Vec3f& n, const Vec3f& l, const Vec3f& v) {
    const auto sine = [](const Vec3f& a, const Vec3f& b) { return a.normalized().cross(b.normalized()).norm(); };
    const Vec3f h = (l + v).normalized();
    const auto lobe = [&](float ks, float alpha, float shift, const Vec3f& colour) -> Vec3f {
        const Vec3f tilted = t + shift * n;
        return ks * std::pow(sine(tilted, h), alpha) * colour;
    };
    Vec3f out = m.kd * sine(t, l) * m.color + lobe(m.ks, m.shininess, m.primaryShift, m.specularColor);
    if (m.twoLobes) out += lobe(m.secondaryKs, m.secondaryShininess, m.secondaryShift, m.secondaryColor);
    return out;
}

}  // namespace hp::test
