// A point of the smooth curve through a strand's polyline, uniform
// Catmull-Rom (Catmull and Rom 1974; passes through every vertex) or uniform
// cubic B-spline (smoother, approximates the vertices), uTess.z choosing.
// Segment c1 -> c2 of the polyline, at u in [0, 1]; c0 and c3 are its
// neighbours. At a strand's root and tip the patch repeats the end vertex;
// it is mirrored (2b - c) instead, which makes both curves start and end
// exactly at the polyline's ends. Shared by the tessellation (strand.tese)
// and the compute pass that shades the strand vertices (strand_shade.comp),
// so both find the same points.
//   Catmull-Rom: P(u) = 1/2 [2 p1 + (p2 - p0) u + (2 p0 - 5 p1 + 4 p2 - p3) u^2 + (-p0 + 3 p1 - 3 p2 + p3) u^3]
//   B-spline:    P(u) = 1/6 [(1 - u)^3 p0 + (3 u^3 - 6 u^2 + 4) p1 + (-3 u^3 + 3 u^2 + 3 u + 1) p2 + u^3 p3]
void strandCurve(vec3 c0, vec3 p1, vec3 p2, vec3 c3, float u, out vec3 position, out vec3 derivative) {
    vec3 p0 = c0 == p1 ? 2.0 * p1 - p2 : c0;
    vec3 p3 = c3 == p2 ? 2.0 * p2 - p1 : c3;
    float u2 = u * u, u3 = u2 * u;
    if (uTess.z < 0.5) {
        position = 0.5 * (2.0 * p1 + (p2 - p0) * u + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u2 +
                          (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * u3);
        derivative = 0.5 * ((p2 - p0) + 2.0 * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u +
                            3.0 * (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * u2);
    } else {
        float v = 1.0 - u;
        position = (v * v * v * p0 + (3.0 * u3 - 6.0 * u2 + 4.0) * p1 + (-3.0 * u3 + 3.0 * u2 + 3.0 * u + 1.0) * p2 +
                    u3 * p3) / 6.0;
        derivative = (-3.0 * v * v * p0 + (9.0 * u2 - 12.0 * u) * p1 + (-9.0 * u2 + 6.0 * u + 3.0) * p2 +
                      3.0 * u2 * p3) / 6.0;
    }
    if (dot(derivative, derivative) < 1e-20) derivative = p2 - p1;
}
