#include "sim/guides/rod_preload.h"

#include <Eigen/LU>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <vector>

namespace hp::rod {

int headContacts(const Vec3f* x, int n, const strand::HeadQuery& head, float reach, Vec3f* normal) {
    int count = 0;
    normal[0] = Vec3f::Zero();
    for (int i = 1; i < n; ++i) {
        Vec3f g = Vec3f::Zero();
        const float phi = head.distance(x[i], &g);
        const bool near = phi < reach && g.squaredNorm() > 1e-12f;
        normal[i] = near ? Vec3f(g.normalized()) : Vec3f::Zero();
        count += near ? 1 : 0;
    }
    return count;
}

Eigen::VectorXd nonNegativeLeastSquares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
    const Eigen::Index m = A.cols();
    Eigen::VectorXd x = Eigen::VectorXd::Zero(m);
    std::vector<bool> passive(size_t(m), false);  // the active set P: λ free (> 0) there
    // Optimality (Kuhn-Tucker): w = Aᵀ(b - Aλ) ≤ 0 where λ = 0, = 0 where λ > 0.
    const double tol = 1e-12 * (A.norm() * b.norm() + 1e-300);
    for (Eigen::Index round = 0; round <= 3 * m; ++round) {
        const Eigen::VectorXd w = A.transpose() * (b - A * x);
        Eigen::Index t = -1;
        double best = tol;
        for (Eigen::Index j = 0; j < m; ++j)
            if (!passive[size_t(j)] && w[j] > best) best = w[j], t = j;
        if (t < 0) break;
        passive[size_t(t)] = true;
        for (int inner = 0; inner <= 3 * m; ++inner) {
            std::vector<Eigen::Index> idx;
            for (Eigen::Index j = 0; j < m; ++j)
                if (passive[size_t(j)]) idx.push_back(j);
            if (idx.empty()) break;
            Eigen::MatrixXd Ap(A.rows(), Eigen::Index(idx.size()));
            for (size_t k = 0; k < idx.size(); ++k) Ap.col(Eigen::Index(k)) = A.col(idx[k]);
            const Eigen::VectorXd zp = Ap.colPivHouseholderQr().solve(b);
            Eigen::VectorXd z = Eigen::VectorXd::Zero(m);
            bool feasible = true;
            for (size_t k = 0; k < idx.size(); ++k) {
                z[idx[k]] = zp[Eigen::Index(k)];
                feasible = feasible && zp[Eigen::Index(k)] > 0;
            }
            if (feasible) {
                x = z;
                break;
            }
            // Step from λ toward z as far as λ stays ≥ 0; the variables that
            // reach 0 leave the active set.
            double alpha = 1;
            for (Eigen::Index j : idx)
                if (z[j] <= 0) alpha = std::min(alpha, x[j] / (x[j] - z[j]));
            x += alpha * (z - x);
            for (Eigen::Index j : idx)
                if (x[j] <= 1e-15 * (1 + x.cwiseAbs().maxCoeff())) {
                    x[j] = 0;
                    passive[size_t(j)] = false;
                }
        }
    }
    return x;
}

double preloadOffset(const RodStrand& s, const Vec3f* x, const Mat3f& R, const Vec3f* force,
                     const Vec3f* contactNormal, Vec2f* c) {
    const int S = s.vertices - 1;
    if (s.bendStiffness <= 0) return 0;
    const Eigen::FullPivLU<Eigen::MatrixXd> lu(equilibriumMatrix(s, x, R));
    Eigen::VectorXd f(3 * S);
    for (int v = 1; v <= S; ++v)
        for (int k = 0; k < 3; ++k) f[3 * (v - 1) + k] = -double(force[v][k]);
    Eigen::VectorXd lambda = lu.solve(f);
    double carried = 0;
    std::vector<int> leaning;
    for (int v = 1; contactNormal && v <= S; ++v)
        if (contactNormal[v].squaredNorm() > 0.f) leaning.push_back(v);
    if (!leaning.empty()) {
        // Λ(λ) = Λ_0 - B·λ with B's column k = (Jᵀ)⁻¹·n_k at vertex k; the
        // energy's rows are the bend rows weighted by √α_j.
        const Eigen::Index m = Eigen::Index(leaning.size());
        Eigen::MatrixXd N = Eigen::MatrixXd::Zero(3 * S, m);
        for (Eigen::Index k = 0; k < m; ++k)
            for (int d = 0; d < 3; ++d) N(3 * (leaning[size_t(k)] - 1) + d, k) = double(contactNormal[leaning[size_t(k)]][d]);
        const Eigen::MatrixXd B = lu.solve(N);
        Eigen::MatrixXd A(2 * S, m);
        Eigen::VectorXd b(2 * S);
        for (int j = 0; j < S; ++j) {
            const double w = std::sqrt(double(voronoiLength(s, j)) / stiffnessAt(s, j));
            for (int r = 0; r < 2; ++r) {
                A.row(2 * j + r) = w * B.row(3 * j + r);
                b[2 * j + r] = w * lambda[3 * j + r];
            }
        }
        const Eigen::VectorXd push = nonNegativeLeastSquares(A, b);
        lambda -= B * push;
        carried = push.sum();
    }
    for (int j = 0; j < S; ++j) {
        const double alpha = voronoiLength(s, j) / stiffnessAt(s, j);
        c[j] += Vec2f(float(alpha * lambda[3 * j]), float(alpha * lambda[3 * j + 1]));
    }
    return carried;
}

int limitPreload(const RodStrand& s, const Vec2f* c0, float gravity, float limit, Vec2f* c) {
    const int S = s.vertices - 1;
    if (limit <= 0.f || S < 1 || gravity <= 0.f) return 0;
    double mass = 0, length = 0;
    for (int i = 1; i <= S; ++i) mass += s.invMass[i] > 0.f ? 1.0 / double(s.invMass[i]) : 0.0;
    for (int j = 0; j < S; ++j) length += double(s.restLength[j]);
    const double weightPerLength = mass / std::max(length, 1e-12) * double(gravity);  // μ·|g|, N/m
    int clipped = 0;
    for (int j = 0; j < S; ++j) {
        const double bendingLength = std::cbrt(stiffnessAt(s, j) / weightPerLength);
        const float bound = float(double(limit) * double(voronoiLength(s, j)) / bendingLength);
        const Vec2f d = c[j] - c0[j];
        const float norm = d.norm();
        if (norm <= bound) continue;
        c[j] = c0[j] + d * (bound / norm);
        ++clipped;
    }
    return clipped;
}

int preload(const RodStrand& s, const Vec3f* x, const Mat3f& R, const Vec3f& gravity, float h, int probes,
            const PreloadContact& contact, float limit, Vec2f* c, RodScratch& sc) {
    const int n = s.vertices;
    const std::vector<Vec2f> c0(c, c + (n - 1));  // the groom's own curvatures
    std::vector<Vec3f> f(size_t(n), Vec3f::Zero()), xt(size_t(n), Vec3f::Zero()), vt(size_t(n), Vec3f::Zero());
    std::vector<Vec3f> normal(size_t(n), Vec3f::Zero());
    const bool leans = contact.head && contact.head->collider &&
                       headContacts(x, n, *contact.head, contact.radius + contact.reach, normal.data()) > 0;
    const Vec3f* leaning = leans ? normal.data() : nullptr;
    // The probes step as the simulation will: with the head where the
    // strand leans on it (it holds those vertices up), else without (a
    // strand out of reach of the head does not touch it in one step).
    const strand::HeadQuery* head = leans ? contact.head : nullptr;
    for (int i = 1; i < n; ++i) f[size_t(i)] = gravity / s.invMass[i];
    preloadOffset(s, x, R, f.data(), leaning, c);
    // The analytic pre-load balances the forces at x; rodStep linearises at
    // its prediction y = x + h²g, about a millimetre away. Each probe step
    // from rest measures the drift δ that remains and cancels its force
    // M·δ/h² the same way. How much each probe gains depends on the strand:
    // ~10× on a free strand, ~1.2× on the default shot's settled guides,
    // whose median drift per step goes 9.3 → 7.2 → 6.5 → 6.0 µm with 0, 1,
    // 2, 3 probes (simulation.preload_probes says so to the user).
    for (int probe = 0; probe < probes; ++probe) {
        for (int i = 0; i < n; ++i) {
            xt[size_t(i)] = x[i];
            vt[size_t(i)] = Vec3f::Zero();
        }
        rodStep(s, xt.data(), vt.data(), x[0], R, gravity, h, 0.f, 0.f, head, contact.radius, sc);
        for (int i = 1; i < n; ++i) f[size_t(i)] = (xt[size_t(i)] - x[i]) / (s.invMass[i] * h * h);
        preloadOffset(s, x, R, f.data(), leaning, c);
    }
    return limitPreload(s, c0.data(), gravity.norm(), limit, c);
}

}  // namespace hp::rod
