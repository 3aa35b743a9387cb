// rod::rodSteps: one XPBD step (sim/guides/rod_kernels.h gives its four
// stages and equations) for up to four strands at once, each strand in one
// SIMD lane (sim/guides/rod_lanes.h) from the prediction through the
// assembly, the banded solve, the stretch pass and the placement of the
// vertices clear of the head; a vertex that meets the head (or cannot keep
// its length) takes the scalar path, and the signed-distance queries (a
// virtual call) are one per lane. Each lane computes what the single-strand
// arithmetic does, operation for operation, so a strand's result is the
// same whatever the batch, the lane or the thread count.
//
// Layout: lane-major structure of arrays. y[i] holds vertex i of the four
// strands (V3 of F4), grad[3r + slot] the gradient of row r on the row's
// vertex `slot`, and the banded system's entry A(r, r-k) of the four
// strands is band[r·(kBand+1) + k] (a D4). Idle lanes (fewer than four
// strands) repeat lane 0's strand and are dropped at the end.
#include "sim/guides/rod_kernels.h"
#include "sim/guides/rod_band.h"

#include "sim/collision/segment_escape.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

// See rod_lanes.h: D4 values never cross a library boundary.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace hp::rod {

using lanes::D4;
using lanes::F4;
using V3 = lanes::V3<F4>;

namespace {

static_assert(kLanes == 4, "rod_lanes.h packs four strands per SIMD register");

/// rod::stretchSolve (rod_kernels.h gives its equations) in four lanes;
/// diag, rhs, dir and cosine are scratch of n entries.
void stretchSolve(V3* x, const F4* w, const F4* rest, int n, D4* diag, D4* rhs, V3* dir, F4* cosine) {
    const int S = n - 1;
    for (int j = 0; j < S; ++j) {
        const V3 e = x[j + 1] - x[j];
        const F4 len = lanes::norm(e);
        dir[j] = e / len;
        rhs[j] = -(lanes::widen(len) - lanes::widen(rest[j]));
    }
    for (int j = 0; j + 1 < S; ++j) cosine[j] = lanes::dot(dir[j], dir[j + 1]);
    // Forward elimination: diag holds the modified pivots.
    for (int j = 0; j < S; ++j) {
        D4 a = lanes::widen(w[j]) + lanes::widen(w[j + 1]);
        if (j > 0) {
            const D4 off = -lanes::widen(w[j]) * lanes::widen(cosine[j - 1]);
            const D4 f = off / diag[j - 1];
            a -= f * off;
            rhs[j] -= f * rhs[j - 1];
        }
        diag[j] = a;
    }
    for (int j = S - 1; j >= 0; --j) {
        if (j + 1 < S) rhs[j] -= -lanes::widen(w[j + 1]) * lanes::widen(cosine[j]) * rhs[j + 1];
        rhs[j] /= diag[j];
    }
    for (int j = 0; j < S; ++j) {
        const V3 dl = lanes::narrow(rhs[j]) * dir[j];
        x[j] = x[j] - w[j] * dl;
        x[j + 1] = x[j + 1] + w[j + 1] * dl;
    }
}

/// Lane l of a lane vector, and writing it.
inline Vec3f lane(const V3& v, int l) { return Vec3f(v.x[l], v.y[l], v.z[l]); }
inline void setLane(V3& v, int l, const Vec3f& p) {
    v.x[l] = p.x();
    v.y[l] = p.y();
    v.z[l] = p.z();
}

/// Steps 1–2 of rodStep up to the solve: predicts y, writes the constraint
/// gradients (rows a, b, stretch of joint j at 3j..3j+2, slots j-1, j, j+1)
/// and the system A = J W Jᵀ + α̃ with right-hand side -C(y), for the four
/// lanes (src[l]: the target in lane l).
/// h: the step of the prediction and of α̃ (BDF2's h', rod_kernels.h
/// bdf2Step); with history, the prediction starts from x̄, v̄ (bdf2Extrapolate),
/// kept in sc.start for the velocities.
void assemble(const RodStepTarget* t, const int* src, const Vec3f& gravity, float h, bool holonomy, RodScratch& sc) {
    const RodStrand& s0 = *t[0].strand;
    const int n = s0.vertices, S = n - 1;
    V3* y = sc.y.data();
    V3* grad = sc.grad.data();
    D4* band = lanes::view(sc.band);
    D4* rhs = lanes::view(sc.rhs);
    F4* w = sc.w.data();
    F4* rest = sc.rest.data();

    // Per-lane constants: masses, rest lengths, the start of the frame, α̃.
    V3 u, a;
    F4 bendLane{};  // nonzero where the strand bends (EI > 0)
    for (int l = 0; l < kLanes; ++l) {
        const RodStepTarget& tl = t[src[l]];
        const RodStrand& s = *tl.strand;
        for (int i = 0; i < n; ++i) w[i][l] = s.invMass[i];
        for (int j = 0; j < S; ++j) rest[j][l] = s.restLength[j];
        const Vec3f ul = (tl.rootFrame * s.ghostDir).normalized();
        setLane(u, l, ul);
        setLane(a, l, frameStart(tl.rootFrame, ul));
        bendLane[l] = s.bendStiffness > 0 ? 1.f : 0.f;
        // 1. Prediction y = x + h·v + h²·g; the root at its target.
        setLane(y[0], l, tl.rootPos);
        if (tl.xBack) {
            for (int i = 0; i < n; ++i) {
                const Vec3f xs = bdf2Extrapolate(tl.x[i], tl.xBack[i]);
                setLane(sc.start[size_t(i)], l, xs);
                if (i > 0) setLane(y[i], l, xs + h * bdf2Extrapolate(tl.v[i], tl.vBack[i]) + (h * h) * gravity);
            }
        } else {
            for (int i = 0; i < n; ++i) setLane(sc.start[size_t(i)], l, tl.x[i]);
            for (int i = 1; i < n; ++i) setLane(y[i], l, tl.x[i] + h * tl.v[i] + (h * h) * gravity);
        }
    }
    const auto bends = bendLane != 0.f;
    F4 ulen = lanes::splat<F4>(1.f);

    // Constraint rows and gradients at y, joint by joint along the transported frame.
    for (int j = 0; j < S; ++j) {
        const V3 e = y[j + 1] - y[j];
        const Vec2f* rc[kLanes];  // rest curvatures of joint j
        D4 alpha{};
        for (int l = 0; l < kLanes; ++l) {
            const RodStrand& s = *t[src[l]].strand;
            rc[l] = &s.restCurvature[j];
            // α̃ = l̄_j/(EI_j h²), rounded as (EI_j·h)·h
            alpha[l] = double(voronoiLength(s, j)) / (stiffnessAt(s, j) * double(h) * h);
        }
        const F4 c[2] = {F4{(*rc[0])[0], (*rc[1])[0], (*rc[2])[0], (*rc[3])[0]},
                         F4{(*rc[0])[1], (*rc[1])[1], (*rc[2])[1], (*rc[3])[1]}};
        F4 C[2];
        V3 g[2][3];
        lanes::bendRows(u, ulen, e, a, c, j == 0, C, g);
        if (holonomy) {
            // Curled lanes (rod_holonomy.cpp): K_j = C_j + c_j, the reference
            // twist's gradients κb_j/(2|e_j|) and κb_j/(2|e_{j-1}|) (none at
            // the ghost joint), α̃ per row.
            const F4 len = lanes::norm(e);
            const V3 d = e / len;
            const F4 cosTurn = 1.f + lanes::dot(u, d);
            const F4 denom = lanes::select(cosTurn < 1e-4f, lanes::splat<F4>(1e-4f), cosTurn);
            const V3 kb = (2.f * lanes::cross(u, d)) / denom;
            sc.curlA[size_t(j)] = C[0] + c[0];
            sc.curlB[size_t(j)] = C[1] + c[1];
            sc.twistEdge[size_t(j)] = kb / (2.f * len);
            sc.twistParent[size_t(j)] = j == 0 ? V3{} : kb / (2.f * ulen);
            D4* alphaRow = lanes::view(sc.alphaRow);
            alphaRow[3 * j] = alphaRow[3 * j + 1] = alpha;
            alphaRow[3 * j + 2] = D4{};
        }
        for (int k = 0; k < 2; ++k) {
            const int r = 3 * j + k;
            // A strand without bending stiffness has inert bend rows
            // (A = 1, C = 0, no gradient: Δλ = 0).
            for (int slot = j == 0 ? 1 : 0; slot < 3; ++slot)
                grad[3 * r + slot] = lanes::select(bends, g[k][slot], V3{});
            rhs[r] = lanes::widen(lanes::select(bends, -C[k], F4{}));
            for (int l = 0; l < kLanes; ++l) band[size_t(r) * kRowLen][l] = bendLane[l] != 0.f ? alpha[l] : 1.0;
        }
        const F4 len = lanes::norm(e);
        const V3 d = e / len;
        const int r = 3 * j + 2;
        grad[3 * r] = V3{};  // the stretch row does not touch vertex j-1
        grad[3 * r + 1] = -d;
        grad[3 * r + 2] = d;
        rhs[r] = lanes::widen(-(len - rest[j]));
        lanes::advanceFrame(u, ulen, a, e);
    }

    // A = J W Jᵀ (+ α̃ already on the diagonal), lower band, vertex by
    // vertex: the rows touching free vertex v are the bend rows of joints
    // v-1, v, v+1 and the stretch rows of joints v-1, v (at most 8, rows
    // within 7 of each other); each pair adds w_v·g_a·g_b.
    for (int vtx = 1; vtx < n; ++vtx) {
        int rows[8];
        const V3* grads[8];
        int count = 0;
        for (int j = vtx - 1; j <= std::min(vtx + 1, S - 1); ++j) {
            const int slot = vtx - j + 1;
            const int kinds = j <= vtx ? 3 : 2;  // joint v+1's stretch row does not touch v
            for (int k = 0; k < kinds; ++k) {
                rows[count] = 3 * j + k;
                grads[count++] = &grad[3 * (3 * j + k) + slot];
            }
        }
        for (int p = 0; p < count; ++p) {
            const V3 ga = w[vtx] * *grads[p];
            D4* row = band + size_t(rows[p]) * kRowLen;
            for (int q = 0; q <= p; ++q) row[rows[p] - rows[q]] += lanes::widen(lanes::dot(ga, *grads[q]));
        }
    }
}

/// The head as one strand sees it, as a Collider (world points).
class HeadView final : public Collider {
  public:
    explicit HeadView(const strand::HeadQuery& head) : head_(head) {}
    float signedDistance(const Vec3f& p, Vec3f* normal) const override { return head_.distance(p, normal); }

  private:
    const strand::HeadQuery& head_;
};

/// Steps 3–4 at vertex i > 0 of one strand: exact length and head
/// clearance (pinned where both cannot hold: returns true), then its
/// velocity (y - start)/hv. parent: vertex i-1, placed; y: vertex i after
/// the solves, placed here; t.x[i] still holds the step's start and receives
/// y. h: the step's length (the head's motion over it); start, hv: where the
/// integrator's step starts and its length (x[i] and h, or BDF2's x̄ and h').
/// touched: the head placed the vertex (a contact) or it was pinned.
bool placeVertex(const RodStepTarget& t, int i, const Vec3f& parent, Vec3f& y, const Vec3f& start, float h, float hv,
                 float damp, float friction, const strand::HeadQuery* head, float radius, bool& touched) {
    const Vec3f old = t.x[i];
    strand::Contact contact;
    bool pinned = false;
    {
        const float l = t.strand->restLength[i - 1];
        contact = strand::placeSegment(parent, y, l, head, radius);
        const bool lengthOk = std::abs((y - parent).norm() / l - 1.f) < 1e-4f;
        const bool outside = !contact.active || head->distance(y, nullptr) > -0.1f * radius;
        if (!lengthOk || !outside) {
            // No place at its length outside the head: held at its length
            // toward its last valid place, where it was at the step's
            // start, carried along with the head's motion.
            // If the head took that place too, the place at its length
            // outside every part the strand collides with nearest it, else
            // the least deep (segment_escape.h): straight out from the
            // surface under the parent would point into the other surface
            // where two close on the strand (a head tipping onto its neck).
            const Vec3f last = head ? Vec3f(head->toPrevious.inverse() * old) : old;
            y = strand::followTheLeader(parent, last, l);
            if (head && head->distance(y, nullptr) < 0.f) {
                const HeadView view(*head);
                const Vec3f held = y;
                y = escapeSegment(view, parent, l, radius, held, &held).position;
            }
            contact = strand::Contact{};
            pinned = true;
        }
    }
    touched = pinned || contact.active;
    Vec3f vel = (y - start) / hv;
    if (contact.active) vel = strand::contactFriction(vel, head->surfaceVelocity(y, h), contact, friction, hv);
    vel *= damp;
    t.x[i] = y;
    t.v[i] = vel;
    return pinned;
}

}  // namespace

void stretchSolve(Vec3f* x, const float* w, const float* rest, int n) {
    // The strand in every lane: lane 0 is what rodSteps computes for it.
    const size_t m = size_t(n);
    std::vector<V3> y(m), dir(m);
    std::vector<F4> wl(m), rl(m), cosine(m);
    std::vector<lanes::D4Store> diag(m), rhs(m);
    for (int i = 0; i < n; ++i) {
        for (int l = 0; l < kLanes; ++l) setLane(y[size_t(i)], l, x[i]);
        wl[size_t(i)] = lanes::splat<F4>(w[i]);
        if (i + 1 < n) rl[size_t(i)] = lanes::splat<F4>(rest[i]);
    }
    stretchSolve(y.data(), wl.data(), rl.data(), n, lanes::view(diag), lanes::view(rhs), dir.data(), cosine.data());
    for (int i = 0; i < n; ++i) x[i] = lane(y[size_t(i)], 0);
}

HP_ROD_LANES_CLONES int rodSteps(const RodStepTarget* targets, int count, const Vec3f& gravity, float h,
                                  float drag, float friction, const strand::HeadQuery* head, float radius,
                                  RodScratch& sc) {
    const int n = targets[0].strand->vertices, N = 3 * (n - 1);
    sc.y.resize(size_t(n));
    sc.start.resize(size_t(n));
    sc.grad.resize(size_t(N) * 3);
    sc.band.resize(size_t(N) * kRowLen);
    // A accumulates from 0.
    std::memset(static_cast<void*>(sc.band.data()), 0, sc.band.size() * sizeof(lanes::D4Store));
    sc.rhs.resize(size_t(N));
    sc.invD.resize(size_t(N));
    sc.w.resize(size_t(n));
    sc.rest.resize(size_t(n));
    sc.diag.resize(size_t(n));
    sc.lambda.resize(size_t(n));
    sc.dir.resize(size_t(n));
    sc.cosine.resize(size_t(n));
    int src[kLanes];
    for (int l = 0; l < kLanes; ++l) src[l] = l < count ? l : 0;  // idle lanes repeat lane 0

    // BDF2 (rod_kernels.h bdf2Step) where the strands carry history: the
    // implicit Euler step of h' from x̄, v̄; velocities (y - x̄)/h'.
    const bool bdf2 = targets[0].xBack != nullptr;
    const float hv = bdf2 ? bdf2Step(h) : h;
    // Curled strands' lanes (rod::curled) solve with the frame's holonomy
    // (rod_holonomy.cpp); without one, the banded solve alone, as before.
    bool curledLane[kLanes] = {};
    bool anyCurled = false;
    for (int k = 0; k < count; ++k) anyCurled = (curledLane[k] = curled(*targets[k].strand)) || anyCurled;
    if (anyCurled) {
        for (auto* v : {&sc.curlA, &sc.curlB}) v->resize(size_t(n));
        for (auto* v : {&sc.twistEdge, &sc.twistParent}) v->resize(size_t(n));
        sc.alphaRow.resize(size_t(N));
        sc.b.resize(size_t(N));
    }
    assemble(targets, src, gravity, hv, anyCurled, sc);
    // The curled lanes' iterations need the right-hand side the banded solve overwrites.
    if (anyCurled) std::memcpy(static_cast<void*>(sc.b.data()), sc.rhs.data(), size_t(N) * sizeof(lanes::D4Store));
    bandedSolve(lanes::view(sc.band), lanes::view(sc.invD), lanes::view(sc.rhs), N);
    if (anyCurled) holonomyIterate(sc, n, curledLane);
    // 2. y += W Jᵀ Δλ: row r of joint r/3 moves its vertices j-1, j, j+1;
    // in a curled lane also -Σ_k T_k ∇m_k (rod_kernels.h constraintJacobian).
    V3* y = sc.y.data();
    const F4* w = sc.w.data();
    for (int r = 0; r < N; ++r) {
        const F4 dl = lanes::narrow(lanes::view(sc.rhs)[r]);
        for (int slot = 0; slot < 3; ++slot) {
            const int vtx = r / 3 - 1 + slot;
            if (vtx >= 1) y[vtx] = y[vtx] + (w[vtx] * dl) * sc.grad[size_t(3 * r + slot)];
        }
    }
    if (anyCurled) {
        const D4* dl = lanes::view(sc.rhs);
        F4 mask{};
        for (int k = 0; k < count; ++k) mask[k] = curledLane[k] ? 1.f : 0.f;
        const auto on = mask != 0.f;  // the other lanes keep their bits
        D4 T{};
        for (int k = n - 2; k >= 0; --k) {
            const F4 Tk = lanes::narrow(T);
            const V3 gE = Tk * sc.twistEdge[size_t(k)], gP = Tk * sc.twistParent[size_t(k)];
            y[k + 1] = lanes::select(on, y[k + 1] - w[k + 1] * gE, y[k + 1]);
            if (k >= 1) y[k] = lanes::select(on, y[k] + w[k] * (gE - gP), y[k]);
            if (k >= 2) y[k - 1] = lanes::select(on, y[k - 1] + w[k - 1] * gP, y[k - 1]);
            T += lanes::widen(sc.curlB[size_t(k)]) * dl[3 * k] - lanes::widen(sc.curlA[size_t(k)]) * dl[3 * k + 1];
        }
    }
    stretchSolve(y, w, sc.rest.data(), n, lanes::view(sc.diag), lanes::view(sc.lambda), sc.dir.data(),
                 sc.cosine.data());

    // 3–4. Placement root to tip, vertex by vertex in lanes: where the
    // follow-the-leader point of every lane is clear of the head (no
    // contact, its length exact), the lanes finish together (placeSegment's
    // own first test and result); a lane that meets the head or fails its
    // length takes the scalar path (placeVertex) from its unplaced vertex.
    // The signed-distance queries stay one per lane (a virtual call).
    const float damp = strand::dampingFactor(drag, h);
    const bool collides = head && head->collider;
    // Each lane's view of the head: the parts its strand ignores.
    strand::HeadQuery laneHead[kLanes];
    const strand::HeadQuery* heads[kLanes] = {};
    for (int k = 0; k < count && head; ++k) {
        laneHead[k] = *head;
        laneHead[k].ignoreParts = targets[k].ignoreParts;
        heads[k] = &laneHead[k];
    }
    int pinned = 0;
    for (int i = 0; i < n; ++i) {
        // x_n, v_n: BDF2's next history (placeVertex overwrites a scalar lane's x, v).
        Vec3f oldX[kLanes], oldV[kLanes];
        if (bdf2)
            for (int k = 0; k < count; ++k) {
                oldX[k] = targets[k].x[i];
                oldV[k] = targets[k].v[i];
            }
        bool scalar[kLanes] = {}, touched[kLanes] = {};
        if (i > 0) {
            // followTheLeader: parent + e·(l/|e|), or straight up from a collapsed segment.
            const V3& parent = y[i - 1];
            const V3 e = y[i] - parent;
            const F4 len = lanes::norm(e), l = sc.rest[size_t(i - 1)];
            const V3 up = {parent.x + 0.f * l, parent.y + 1.f * l, parent.z + 0.f * l};
            V3 placed = lanes::select(len > 1e-12f, parent + (l / len) * e, up);
            const F4 q = lanes::norm(placed - parent) / l - 1.f;
            const auto exact = lanes::select(q < 0.f, -q, q) < 1e-4f;
            for (int k = 0; k < count; ++k) {
                scalar[k] = !exact[k] || (collides && !(heads[k]->distance(lane(placed, k), nullptr) >= radius));
                if (!scalar[k]) continue;
                Vec3f child = lane(y[i], k);
                pinned += placeVertex(targets[k], i, lane(parent, k), child, lane(sc.start[size_t(i)], k), h, hv,
                                      damp, friction, heads[k], radius, touched[k]);
                setLane(placed, k, child);
            }
            y[i] = placed;
        }
        V3 vel = (y[i] - sc.start[size_t(i)]) / hv;
        if (i > 0) vel = damp * vel;
        for (int k = 0; k < count; ++k) {
            if (!scalar[k]) {
                targets[k].x[i] = lane(y[i], k);
                targets[k].v[i] = lane(vel, k);
            }
            if (bdf2 && touched[k]) {
                // A vertex the head placed or pinned starts its history
                // afresh (rod_kernels.h bdf2Start): the contact took its
                // velocity into the head away, and BDF2's extrapolation
                // would carry that change on, v̄ = v + (v - v_{n-1})/3,
                // as a bounce off the surface.
                bdf2Start(&targets[k].x[i], &targets[k].v[i], 1, h, &targets[k].xBack[i], &targets[k].vBack[i]);
            } else if (bdf2) {
                targets[k].xBack[i] = oldX[k];
                targets[k].vBack[i] = oldV[k];
            }
        }
    }
    return pinned;
}

int rodStep(const RodStrand& s, Vec3f* x, Vec3f* v, const Vec3f& rootPos, const Mat3f& rootFrame,
            const Vec3f& gravity, float h, float drag, float friction, const strand::HeadQuery* head, float radius,
            RodScratch& sc) {
    const RodStepTarget t{&s, x, v, rootPos, rootFrame};
    return rodSteps(&t, 1, gravity, h, drag, friction, head, radius, sc);
}

}  // namespace hp::rod
