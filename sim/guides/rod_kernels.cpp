#include "sim/guides/rod_kernels.h"


#include <algorithm>
#include <cmath>
#include <vector>

namespace hp::rod {
namespace {

inline lanes::V3<float> toLanes(const Vec3f& v) { return {v.x(), v.y(), v.z()}; }
inline Vec3f fromLanes(const lanes::V3<float>& v) { return Vec3f(v.x, v.y, v.z); }

/// Walks a strand's joints root to tip with the transported frame: calls
/// f(j, parentDir, parentLen, e_j, a_j, ghost) for each joint.
template <typename F>
void forJoints(const RodStrand& s, const Vec3f* x, const Mat3f& R, F&& f) {
    const Vec3f u0 = (R * s.ghostDir).normalized();
    lanes::V3<float> u = toLanes(u0), a = toLanes(frameStart(R, u0));
    float ulen = 1.f;
    for (int j = 0; j + 1 < s.vertices; ++j) {
        const Vec3f e = x[j + 1] - x[j];
        f(j, fromLanes(u), ulen, e, fromLanes(a), j == 0);
        lanes::advanceFrame(u, ulen, a, toLanes(e));
    }
}

}  // namespace

Vec3f frameStart(const Mat3f& R, const Vec3f& d) {
    Vec3f a = R.col(0) - R.col(0).dot(d) * d;
    if (a.squaredNorm() < 1e-6f) a = R.col(2) - R.col(2).dot(d) * d;
    return a.normalized();
}

Vec2f bendConstraint(const Vec3f& u, float parentLen, const Vec3f& e, const Vec3f& a, const Vec2f& c, bool ghost,
                     Vec3f g[2][3]) {
    const float cl[2] = {c[0], c[1]};
    float C[2];
    lanes::V3<float> gl[2][3];
    lanes::bendRows(toLanes(u), parentLen, toLanes(e), toLanes(a), cl, ghost, C, gl);
    for (int k = 0; k < 2; ++k) {
        g[k][0] = ghost ? Vec3f::Zero() : fromLanes(gl[k][0]);
        g[k][1] = fromLanes(gl[k][1]);
        g[k][2] = fromLanes(gl[k][2]);
    }
    return Vec2f(C[0], C[1]);
}

bool curled(const RodStrand& s) {
    if (s.bendStiffness <= 0 || !s.restCurvature) return false;
    for (int j = 0; j + 1 < s.vertices; ++j)
        if (std::abs(s.restCurvature[j][0]) > kStraightTurn || std::abs(s.restCurvature[j][1]) > kStraightTurn)
            return true;
    return false;
}

void constraintJacobian(const RodStrand& s, const Vec3f* x, const Mat3f& R, bool holonomy, Eigen::MatrixXd& J,
                        Eigen::VectorXd* C) {
    const int S = s.vertices - 1;
    J.setZero(3 * S, 3 * S);
    if (C) C->resize(3 * S);
    // ∇ψ_j over the free vertices' coordinates: ψ_0 = 0, ψ_{j+1} = ψ_j - m_j.
    Eigen::VectorXd gradPsi = Eigen::VectorXd::Zero(holonomy ? 3 * S : 0);
    auto addAt = [&](Eigen::VectorXd& row, int v, const Eigen::Vector3d& g) {
        if (v >= 1) row.segment<3>(3 * (v - 1)) += g;
    };
    forJoints(s, x, R, [&](int j, const Vec3f& u, float ulen, const Vec3f& e, const Vec3f& a, bool ghost) {
        Vec3f g[2][3];
        const Vec2f c = s.restCurvature ? s.restCurvature[j] : Vec2f::Zero();
        const Vec2f Cj = bendConstraint(u, ulen, e, a, c, ghost, g);
        const float len = e.norm();
        const Vec3f d = e / len;
        for (int slot = 0; slot < 3; ++slot) {
            const int v = j - 1 + slot;  // free vertex v has columns 3(v-1)..3(v-1)+2
            if (v < 1) continue;
            const Vec3f gs = slot == 2 ? d : slot == 1 ? Vec3f(-d) : Vec3f::Zero();
            for (int k = 0; k < 3; ++k) {
                J(3 * j, 3 * (v - 1) + k) = double(g[0][slot][k]);
                J(3 * j + 1, 3 * (v - 1) + k) = double(g[1][slot][k]);
                J(3 * j + 2, 3 * (v - 1) + k) = double(gs[k]);
            }
        }
        if (C) {
            (*C)[3 * j] = double(Cj[0]);
            (*C)[3 * j + 1] = double(Cj[1]);
            (*C)[3 * j + 2] = double(len) - double(s.restLength[j]);
        }
        if (!holonomy) return;
        // ∂C_j/∂ψ_j = (K_2, -K_1): the frame turned by δψ about d_{j-1}.
        const Vec2f K = Cj + c;
        J.row(3 * j) += double(K[1]) * gradPsi.transpose();
        J.row(3 * j + 1) -= double(K[0]) * gradPsi.transpose();
        // The reference twist of joint j: ∂m_j/∂e_j = κb_j/(2|e_j|),
        // ∂m_j/∂e_{j-1} = κb_j/(2|e_{j-1}|) (none at the ghost joint).
        const Eigen::Vector3d kb = (2.f * u.cross(d) / std::max(1.f + u.dot(d), 1e-4f)).cast<double>();
        const Eigen::Vector3d gEdge = kb / (2.0 * double(len));
        addAt(gradPsi, j + 1, -gEdge);
        addAt(gradPsi, j, gEdge);
        if (!ghost) {
            const Eigen::Vector3d gParent = kb / (2.0 * double(ulen));
            addAt(gradPsi, j, -gParent);
            addAt(gradPsi, j - 1, gParent);
        }
    });
}

Eigen::MatrixXd equilibriumMatrix(const RodStrand& s, const Vec3f* x, const Mat3f& R) {
    Eigen::MatrixXd J;
    constraintJacobian(s, x, R, true, J, nullptr);
    return J.transpose();
}

void restCurvature(const RodStrand& s, const Vec3f* x, const Mat3f& R, Vec2f* c) {
    forJoints(s, x, R, [&](int j, const Vec3f& u, float ulen, const Vec3f& e, const Vec3f& a, bool ghost) {
        Vec3f g[2][3];
        c[j] = bendConstraint(u, ulen, e, a, Vec2f::Zero(), ghost, g);  // C_j(x) = 0
    });
}

void holonomyForce(const RodStrand& s, const Vec3f* x, const Mat3f& R, Vec3f* force) {
    const int S = s.vertices - 1;
    if (s.bendStiffness <= 0 || S < 2) return;
    // Per joint: τ_j = ∂E_j/∂ψ_j and the turn's κb_k with its two edge lengths.
    const size_t m = static_cast<size_t>(S);
    std::vector<double> tau(m, 0.0);
    std::vector<Vec3f> kb(m);
    std::vector<float> parentLen(m);
    forJoints(s, x, R, [&](int j, const Vec3f& u, float ulen, const Vec3f& e, const Vec3f& a, bool ghost) {
        Vec3f g[2][3];
        const Vec2f c = s.restCurvature[j];
        const Vec2f C = bendConstraint(u, ulen, e, a, c, ghost, g);
        const Vec2f K = C + c;
        // E_j = k_j/2 |K_j - c_j|², and turning the frame by δψ about u turns
        // K by δK = δψ·(K_2, -K_1): τ_j = k_j (c_2 K_1 - c_1 K_2).
        const double k = stiffnessAt(s, j) / double(voronoiLength(s, j));
        tau[size_t(j)] = k * (double(c[1]) * K[0] - double(c[0]) * K[1]);
        const Vec3f d = e.normalized();
        kb[size_t(j)] = 2.f * u.cross(d) / std::max(1.f + u.dot(d), 1e-4f);
        parentLen[size_t(j)] = ghost ? 0.f : ulen;
    });
    // F = -Σ_k T_k ∇m_k with T_k = Σ_{j>k} τ_j (the frame of joint j is
    // transported through the turns of joints 0..j-1), from the tip.
    double T = 0;
    for (int k = S - 1; k >= 0; --k) {
        const Vec3f gEdge = kb[size_t(k)] / (2.f * (x[k + 1] - x[k]).norm());  // ∂m_k/∂e_k
        const float Tf = float(T);
        force[k + 1] += Tf * gEdge;  // sign: ψ_j = -Σ m_k (space-parallel against time-parallel)
        force[k] -= Tf * gEdge;
        if (parentLen[size_t(k)] > 0.f) {
            const Vec3f gParent = kb[size_t(k)] / (2.f * parentLen[size_t(k)]);  // ∂m_k/∂e_{k-1}
            force[k] += Tf * gParent;
            force[k - 1] -= Tf * gParent;
        }
        T += tau[size_t(k)];
    }
}

double bendEnergy(const RodStrand& s, const Vec3f* x, const Mat3f& rootFrame) {
    double e = 0;
    if (s.bendStiffness <= 0) return 0;
    forJoints(s, x, rootFrame, [&](int j, const Vec3f& u, float ulen, const Vec3f& ej, const Vec3f& a, bool ghost) {
        Vec3f g[2][3];
        const Vec2f C = bendConstraint(u, ulen, ej, a, s.restCurvature[j], ghost, g);
        e += stiffnessAt(s, j) / (2.0 * voronoiLength(s, j)) * double(C.squaredNorm());
    });
    return e;
}

}  // namespace hp::rod
