#include "sim/guides/rod_kernels.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>

namespace hp::rod {
namespace {

/// Bandwidth of the XPBD system: rows ordered (bend a, bend b, stretch) per
/// joint; joints j and k share a vertex iff |j - k| ≤ 2, so A(r, s) = 0 for
/// |r - s| > 3·2 + 2.
constexpr int kBand = 8;

/// Voronoi length of joint j: l̄_0 = l_0/2 (clamped end), else (l_{j-1} + l_j)/2.
inline float voronoi(const RodStrand& s, int j) {
    return j == 0 ? 0.5f * s.restLength[0] : 0.5f * (s.restLength[j - 1] + s.restLength[j]);
}

/// Walks a strand's joints root to tip with the transported frame: calls
/// f(j, parentDir, parentLen, e_j, a_j, ghost) for each joint.
template <typename F>
void forJoints(const RodStrand& s, const Vec3f* x, const Mat3f& R, F&& f) {
    Vec3f u = (R * s.ghostDir).normalized();
    float ulen = 1.f;
    Vec3f a = frameStart(R, u);
    for (int j = 0; j + 1 < s.vertices; ++j) {
        const Vec3f e = x[j + 1] - x[j];
        f(j, u, ulen, e, a, j == 0);
        const float len = e.norm();
        const Vec3f d = len > 0.f ? Vec3f(e / len) : u;
        if (1.f + u.dot(d) > 1e-4f) a = transportVector(a, u, d);
        a = (a - a.dot(d) * d).normalized();  // keep the frame orthonormal in float
        u = d;
        ulen = len;
    }
}

/// First column of row i's envelope: a bend row of joint j shares vertex
/// j-1 with the rows of joint j-2 (first column 3(j-2)); a stretch row
/// (vertices j, j+1) meets joint j-1 at the earliest (3(j-1)). LDLᵀ fills
/// only inside this envelope, so the factorization skips the zeros of the
/// band (the same sums, without the terms that are exactly zero).
inline int envelopeStart(int i) {
    const int j = i / 3;
    return std::max(0, i - 3 * j == 2 ? 3 * j - 3 : 3 * j - 6);
}

/// Banded LDLᵀ in place for kLanes independent systems of the same size,
/// interleaved lane by lane (lane l of A(i, i-k) at band[(i·(B+1) + k)·kLanes
/// + l]; rhs and invD likewise), so that the lanes' dependency chains run
/// side by side in SIMD registers. Per lane: L(i, i-k) (k > 0) replaces
/// A(i, i-k), invD receives 1/D(i), then L D Lᵀ z = rhs is solved in place:
///   D_i = A_ii - Σ_m L_im² D_m,  L_ij = (A_ij - Σ_m L_im D_m L_jm) / D_j,
/// the sums over the envelope (envelopeStart).
void bandedSolve(double* band, double* invD, double* rhs, int n) {
    constexpr int W = kBand + 1, L = kLanes;
    double t[kBand][L];  // t[m - lo] = L_im·D_m of the current row
    for (int i = 0; i < n; ++i) {
        const int lo = envelopeStart(i);
        double* Li = band + size_t(i) * W * L;
        double d[L];
        for (int l = 0; l < L; ++l) d[l] = Li[l];
        for (int j = lo; j < i; ++j) {
            const double* Lj = band + size_t(j) * W * L;
            double sum[L];
            for (int l = 0; l < L; ++l) sum[l] = Li[(i - j) * L + l];
            for (int m = std::max(lo, envelopeStart(j)); m < j; ++m)
                for (int l = 0; l < L; ++l) sum[l] -= t[m - lo][l] * Lj[(j - m) * L + l];
            for (int l = 0; l < L; ++l) {
                t[j - lo][l] = sum[l];
                const double lij = sum[l] * invD[j * L + l];
                Li[(i - j) * L + l] = lij;
                d[l] -= sum[l] * lij;
            }
        }
        for (int l = 0; l < L; ++l) invD[i * L + l] = 1.0 / d[l];
    }
    for (int i = 0; i < n; ++i) {
        const double* Li = band + size_t(i) * W * L;
        for (int m = envelopeStart(i); m < i; ++m)
            for (int l = 0; l < L; ++l) rhs[i * L + l] -= Li[(i - m) * L + l] * rhs[m * L + l];
    }
    for (int i = 0; i < n * L; ++i) rhs[i] *= invD[i];
    for (int i = n - 1; i >= 0; --i)
        for (int k = i + 1; k <= std::min(n - 1, i + kBand); ++k)
            if (envelopeStart(k) <= i)
                for (int l = 0; l < L; ++l) rhs[i * L + l] -= band[(size_t(k) * W + size_t(k - i)) * L + l] * rhs[k * L + l];
}

}  // namespace

void stretchSolve(Vec3f* x, const float* w, const float* rest, int n, double* diag, double* rhs, Vec3f* dir) {
    const int S = n - 1;
    for (int j = 0; j < S; ++j) {
        const Vec3f e = x[j + 1] - x[j];
        const float len = e.norm();
        dir[j] = e / len;
        rhs[j] = -(double(len) - rest[j]);
    }
    // Forward elimination: diag holds the modified pivots.
    for (int j = 0; j < S; ++j) {
        double a = double(w[j]) + w[j + 1];
        if (j > 0) {
            const double off = -double(w[j]) * dir[j - 1].dot(dir[j]);
            const double f = off / diag[j - 1];
            a -= f * off;
            rhs[j] -= f * rhs[j - 1];
        }
        diag[j] = a;
    }
    for (int j = S - 1; j >= 0; --j) {
        if (j + 1 < S) rhs[j] -= -double(w[j + 1]) * dir[j].dot(dir[j + 1]) * rhs[j + 1];
        rhs[j] /= diag[j];
    }
    for (int j = 0; j < S; ++j) {
        const Vec3f dl = float(rhs[j]) * dir[j];
        x[j] -= w[j] * dl;
        x[j + 1] += w[j + 1] * dl;
    }
}

Vec3f frameStart(const Mat3f& R, const Vec3f& d) {
    Vec3f a = R.col(0) - R.col(0).dot(d) * d;
    if (a.squaredNorm() < 1e-6f) a = R.col(2) - R.col(2).dot(d) * d;
    return a.normalized();
}

Vec2f bendConstraint(const Vec3f& u, float parentLen, const Vec3f& e, const Vec3f& a, const Vec2f& c, bool ghost,
                     Vec3f g[2][3]) {
    const float len = e.norm();
    const Vec3f d = e / len;
    const float denom = std::max(1.f + u.dot(d), 1e-4f);
    const Vec3f kb = 2.f * u.cross(d) / denom;
    const Vec3f axes[2] = {a, u.cross(a)};
    Vec2f C;
    for (int k = 0; k < 2; ++k) {
        const Vec3f& ax = axes[k];
        const float kbAx = kb.dot(ax);
        C[k] = kbAx - c[k];
        // ∂κb/∂d = (2[u]× - κb uᵀ)/(1+u·d), ∂κb/∂u = (-2[d]× - κb dᵀ)/(1+u·d),
        // ∂d/∂x_{j+1} = (I - d dᵀ)/|e_j|, ∂u/∂x_j = (I - u uᵀ)/|e_{j-1}|.
        const Vec3f td = (-2.f * u.cross(ax) - kbAx * u) / denom;
        const Vec3f gd = (td - d.dot(td) * d) / len;
        g[k][2] = gd;
        if (ghost) {
            g[k][1] = -gd;
            g[k][0] = Vec3f::Zero();
        } else {
            const Vec3f tu = (2.f * d.cross(ax) - kbAx * d) / denom;
            const Vec3f gu = (tu - u.dot(tu) * u) / parentLen;
            g[k][1] = gu - gd;
            g[k][0] = -gu;
        }
    }
    return C;
}

void preloadOffset(const RodStrand& s, const Vec3f* x, const Mat3f& R, const Vec3f* force, Vec2f* c) {
    const int S = s.vertices - 1;
    if (s.bendStiffness <= 0) return;
    Eigen::MatrixXd Jt = Eigen::MatrixXd::Zero(3 * S, 3 * S);
    forJoints(s, x, R, [&](int j, const Vec3f& u, float ulen, const Vec3f& e, const Vec3f& a, bool ghost) {
        Vec3f g[2][3];
        bendConstraint(u, ulen, e, a, Vec2f::Zero(), ghost, g);
        const Vec3f d = e.normalized();
        for (int slot = 0; slot < 3; ++slot) {
            const int v = j - 1 + slot;  // free vertex v has unknowns 3(v-1)..3(v-1)+2
            if (v < 1) continue;
            const Vec3f gs = slot == 2 ? d : slot == 1 ? Vec3f(-d) : Vec3f::Zero();
            for (int k = 0; k < 3; ++k) {
                Jt(3 * (v - 1) + k, 3 * j) = g[0][slot][k];
                Jt(3 * (v - 1) + k, 3 * j + 1) = g[1][slot][k];
                Jt(3 * (v - 1) + k, 3 * j + 2) = gs[k];
            }
        }
    });
    Eigen::VectorXd f(3 * S);
    for (int v = 1; v <= S; ++v)
        for (int k = 0; k < 3; ++k) f[3 * (v - 1) + k] = -double(force[v][k]);
    // Jᵀ is block triangular from the tip (vertex n-1 appears only in the
    // last joint's three rows), so it is invertible.
    const Eigen::VectorXd lambda = Jt.fullPivLu().solve(f);
    for (int j = 0; j < S; ++j) {
        const double alpha = voronoi(s, j) / s.bendStiffness;
        c[j] += Vec2f(float(alpha * lambda[3 * j]), float(alpha * lambda[3 * j + 1]));
    }
}

void restCurvature(const RodStrand& s, const Vec3f* x, const Mat3f& R, Vec2f* c) {
    forJoints(s, x, R, [&](int j, const Vec3f& u, float ulen, const Vec3f& e, const Vec3f& a, bool ghost) {
        Vec3f g[2][3];
        c[j] = bendConstraint(u, ulen, e, a, Vec2f::Zero(), ghost, g);  // C_j(x) = 0
    });
}

void preload(const RodStrand& s, const Vec3f* x, const Mat3f& R, const Vec3f& gravity, float h, Vec2f* c,
             RodScratch& sc) {
    const int n = s.vertices;
    std::vector<Vec3f> f(size_t(n), Vec3f::Zero()), xt(size_t(n), Vec3f::Zero()), vt(size_t(n), Vec3f::Zero());
    for (int i = 1; i < n; ++i) f[size_t(i)] = gravity / s.invMass[i];
    preloadOffset(s, x, R, f.data(), c);
    // The analytic pre-load balances the forces at x; rodStep linearises at
    // its prediction y = x + h²g, about a millimetre away. Each probe step
    // from rest measures the drift δ that remains and cancels its force
    // M·δ/h² the same way (measured: the error shrinks ~10× per probe).
    for (int probe = 0; probe < 3; ++probe) {
        for (int i = 0; i < n; ++i) {
            xt[size_t(i)] = x[i];
            vt[size_t(i)] = Vec3f::Zero();
        }
        rodStep(s, xt.data(), vt.data(), x[0], R, gravity, h, 0.f, 0.f, nullptr, 0.f, sc);
        for (int i = 1; i < n; ++i) f[size_t(i)] = (xt[size_t(i)] - x[i]) / (s.invMass[i] * h * h);
        preloadOffset(s, x, R, f.data(), c);
    }
}

namespace {

/// Steps 1–2 of rodStep up to the solve, for one strand in lane `lane`:
/// predicts y (old: the step's start), writes the constraint gradients
/// (9 per joint: rows a, b, stretch × slots j-1, j, j+1) and the lane's
/// system A = J W Jᵀ + α̃ and right-hand side -C(y).
void assemble(const RodStepTarget& t, const Vec3f& gravity, float h, int lane, Vec3f* y, Vec3f* old, Vec3f* grad,
              double* band, double* rhs) {
    const RodStrand& s = *t.strand;
    const int n = s.vertices, S = n - 1;
    constexpr int W = kBand + 1;
    auto A = [&](int r, int k) -> double& { return band[(size_t(r) * W + size_t(k)) * kLanes + size_t(lane)]; };
    auto b = [&](int r) -> double& { return rhs[size_t(r) * kLanes + size_t(lane)]; };
    for (int i = 0; i < n; ++i) old[i] = t.x[i];
    y[0] = t.rootPos;
    for (int i = 1; i < n; ++i) y[i] = t.x[i] + h * t.v[i] + (h * h) * gravity;

    // Constraint rows and gradients at y.
    const bool bend = s.bendStiffness > 0;
    forJoints(s, y, t.rootFrame, [&](int j, const Vec3f& u, float ulen, const Vec3f& e, const Vec3f& a, bool ghost) {
        Vec3f* g = &grad[size_t(3 * j) * 3];
        if (bend) {
            Vec3f gb[2][3];
            const Vec2f C = bendConstraint(u, ulen, e, a, s.restCurvature[j], ghost, gb);
            for (int k = 0; k < 2; ++k) {
                for (int slot = 0; slot < 3; ++slot) g[k * 3 + slot] = gb[k][slot];
                b(3 * j + k) = -C[k];
                A(3 * j + k, 0) = voronoi(s, j) / (s.bendStiffness * double(h) * h);  // α̃
            }
        } else {
            for (int k = 0; k < 2; ++k) A(3 * j + k, 0) = 1.0;  // inert rows: Δλ = 0
        }
        const float len = e.norm();
        const Vec3f d = e / len;
        g[6 + 1] = -d;
        g[6 + 2] = d;
        b(3 * j + 2) = -(len - s.restLength[j]);
    });
    // A = J W Jᵀ (+ α̃ already on the diagonal), lower band, vertex by
    // vertex: the rows touching free vertex v are the bend rows of joints
    // v-1, v, v+1 and the stretch rows of joints v-1, v (at most 8, rows
    // within 7 of each other); each pair adds w_v·g_a·g_b.
    for (int vtx = 1; vtx < n; ++vtx) {
        int rows[8];
        const Vec3f* grads[8];
        int count = 0;
        for (int j = vtx - 1; j <= std::min(vtx + 1, S - 1); ++j) {
            const int slot = vtx - j + 1;
            const int kinds = j <= vtx ? 3 : 2;  // joint v+1's stretch row does not touch v
            for (int k = 0; k < kinds; ++k) {
                rows[count] = 3 * j + k;
                grads[count++] = &grad[size_t(3 * j + k) * 3 + size_t(slot)];
            }
        }
        const float w = s.invMass[vtx];
        for (int p = 0; p < count; ++p) {
            const Vec3f ga = w * *grads[p];
            for (int q = 0; q <= p; ++q) A(rows[p], rows[p] - rows[q]) += double(ga.dot(*grads[q]));
        }
    }
}

/// Steps 2 (the update y += W Jᵀ Δλ, Δλ in lane `lane` of rhs) to 4 of
/// rodStep for one strand. Returns its pinned vertices.
int finish(const RodStepTarget& t, int lane, const double* rhs, const Vec3f* grad, Vec3f* y, const Vec3f* old,
           float h, float drag, float friction, const strand::HeadQuery* head, float radius, RodScratch& sc) {
    const RodStrand& s = *t.strand;
    const int n = s.vertices, N = 3 * (n - 1);
    for (int r = 0; r < N; ++r) {
        const int jr = r / 3;
        const float dl = float(rhs[size_t(r) * kLanes + size_t(lane)]);
        for (int slot = 0; slot < 3; ++slot) {
            const int vtx = jr - 1 + slot;
            if (vtx >= 1) y[vtx] += (s.invMass[vtx] * dl) * grad[size_t(r) * 3 + size_t(slot)];
        }
    }

    stretchSolve(y, s.invMass, s.restLength, n, sc.diag.data(), sc.lambda.data(), sc.dir.data());

    // Exact lengths and head clearance, root to tip; pinning where both cannot hold.
    const float damp = strand::dampingFactor(drag, h);
    int pinned = 0;
    for (int i = 0; i < n; ++i) {
        strand::Contact contact;
        if (i > 0) {
            const float l = s.restLength[i - 1];
            contact = strand::placeSegment(y[i - 1], y[i], l, head, radius);
            const bool lengthOk = std::abs((y[i] - y[i - 1]).norm() / l - 1.f) < 1e-4f;
            const bool outside = !contact.active || head->distance(y[i], nullptr) > -0.1f * radius;
            if (!lengthOk || !outside) {
                // No place at its length outside the head: held at its length
                // toward its last valid place, where it was at the step's
                // start, carried along with the head's motion.
                // If the head took that place too, straight out from the
                // surface under the parent (outside whenever the head is
                // locally convex there).
                const Vec3f last = head ? Vec3f(head->toPrevious.inverse() * old[i]) : old[i];
                y[i] = strand::followTheLeader(y[i - 1], last, l);
                Vec3f normal;
                if (head && head->distance(y[i], nullptr) < 0.f) {
                    head->distance(y[i - 1], &normal);
                    y[i] = y[i - 1] + l * normal.normalized();
                }
                contact = strand::Contact{};
                ++pinned;
            }
        }
        Vec3f vel = (y[i] - old[i]) / h;
        if (i > 0) {
            if (contact.active) vel = strand::contactFriction(vel, head->surfaceVelocity(y[i], h), contact, friction, h);
            vel *= damp;
        }
        t.x[i] = y[i];
        t.v[i] = vel;
    }
    return pinned;
}

}  // namespace

int rodSteps(const RodStepTarget* targets, int count, const Vec3f& gravity, float h, float drag, float friction,
             const strand::HeadQuery* head, float radius, RodScratch& sc) {
    const int n = targets[0].strand->vertices, N = 3 * (n - 1);
    const size_t gradPerLane = size_t(N) * 3, posPerLane = size_t(n) * 2;
    sc.grad.assign(gradPerLane * kLanes, Vec3f::Zero());
    sc.band.assign(size_t(N) * (kBand + 1) * kLanes, 0.0);
    sc.rhs.assign(size_t(N) * kLanes, 0.0);
    sc.invD.resize(size_t(N) * kLanes);
    sc.a.resize(posPerLane * kLanes);
    sc.diag.resize(size_t(n));
    sc.lambda.resize(size_t(n));
    sc.dir.resize(size_t(n));
    for (int l = 0; l < kLanes; ++l) {
        if (l < count) {
            Vec3f* y = &sc.a[posPerLane * size_t(l)];
            assemble(targets[l], gravity, h, l, y, y + n, &sc.grad[gradPerLane * size_t(l)], sc.band.data(),
                     sc.rhs.data());
        } else {
            for (int r = 0; r < N; ++r) sc.band[size_t(r) * (kBand + 1) * kLanes + size_t(l)] = 1.0;  // idle lane: I z = 0
        }
    }
    bandedSolve(sc.band.data(), sc.invD.data(), sc.rhs.data(), N);
    int pinned = 0;
    for (int l = 0; l < count; ++l) {
        Vec3f* y = &sc.a[posPerLane * size_t(l)];
        pinned += finish(targets[l], l, sc.rhs.data(), &sc.grad[gradPerLane * size_t(l)], y, y + n, h, drag,
                         friction, head, radius, sc);
    }
    return pinned;
}

int rodStep(const RodStrand& s, Vec3f* x, Vec3f* v, const Vec3f& rootPos, const Mat3f& rootFrame,
            const Vec3f& gravity, float h, float drag, float friction, const strand::HeadQuery* head, float radius,
            RodScratch& sc) {
    const RodStepTarget t{&s, x, v, rootPos, rootFrame};
    return rodSteps(&t, 1, gravity, h, drag, friction, head, radius, sc);
}

double bendEnergy(const RodStrand& s, const Vec3f* x, const Mat3f& rootFrame) {
    double e = 0;
    if (s.bendStiffness <= 0) return 0;
    forJoints(s, x, rootFrame, [&](int j, const Vec3f& u, float ulen, const Vec3f& ej, const Vec3f& a, bool ghost) {
        Vec3f g[2][3];
        const Vec2f C = bendConstraint(u, ulen, ej, a, s.restCurvature[j], ghost, g);
        e += s.bendStiffness / (2.0 * voronoi(s, j)) * double(C.squaredNorm());
    });
    return e;
}

}  // namespace hp::rod
