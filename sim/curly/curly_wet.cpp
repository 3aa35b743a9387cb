// CurlyWetSolver: rest shapes, saturation and the curly guides' own step
// (cohesion pass, substeps over the Bullet worlds) plugged into the solver
// skeleton (sim/solver/skeleton.h: time, head interpolation, scene cuts,
// written frames, statistics). The Bullet side is sim/curly/curly_world.cpp.
#include "sim/curly/curly_wet.h"

#include "core/errors.h"
#include "sim/curly/curly_state.h"

#include <algorithm>
#include <cmath>

namespace hp {

using curly::CurlySet;
using curly::Mat3f;
using curly::Quatf;

void CurlyWetSettings::validate() const {
    auto check = [](bool ok, const char* what) {
        if (!ok) throw Error(cat("curly/wet settings: ", what));
    };
    auto finite = [](float v) { return std::isfinite(v); };
    check(particles >= 2 && particles <= 1000, "particles must be in [2, 1000]");
    check(length > 0.f && finite(length), "length must be positive");
    check(curlRadius >= 0.f && curlPitch >= 0.f && finite(curlRadius) && finite(curlPitch),
          "curl radius and pitch must be ≥ 0");
    check(collisionRadius >= 0.f, "collision radius must be ≥ 0");
    check(timeStep > 0.f && finite(timeStep), "time step must be positive");
    check(substeps >= 1 && iterations >= 1, "substeps and iterations must be ≥ 1");
    check(massPerLength > 0.f || massPerLength < 0.f, "mass per length must be positive (or kFromMaterial)");
    if (massPerLength < 0.f || bendStiffness < 0.f || coreStiffness < 0.f)
        check(material.youngs > 0.f && material.shear > 0.f && material.density > 0.f && material.radius > 0.f &&
                  material.hairsPerGuide > 0.f && finite(material.youngs) && finite(material.shear) &&
                  finite(material.density) && finite(material.radius) && finite(material.hairsPerGuide),
              "the material (E, G, density, fibre radius, hairs per guide) must be positive and finite");
    check(gravity.allFinite(), "gravity must be finite");
    check(stretchDamping >= 0.f && bendDamping >= 0.f && coreDamping >= 0.f,
          "spring stiffness and damping must be ≥ 0");
    check(bendSmoothing >= 0.f && coreSmoothing >= 0.f, "smoothing lengths must be ≥ 0");
    check(maxStrain > 0.f && maxStrain < 1.f, "strain limit must be in (0, 1)");
    check(maxRelativeVelocity > 0.f, "velocity limit must be positive");
    check(friction >= 0.f, "friction must be ≥ 0");
    check(saturation >= 0.f && saturation <= 1.f, "saturation must be in [0, 1]");
    check(saturationRoot >= 0.f && saturationTip >= 0.f, "saturation profile must be ≥ 0");
    check(helixRadius >= 0.f && helixPitch >= 0.f && (helixWeight >= 0.f || helixWeight < 0.f),
          "helix radius and pitch must be ≥ 0, the weight a number");
    check(cohesionTightness >= 0.f && cohesionTightness <= 1.f, "cohesion tightness must be in [0, 1]");
    check(cohesionRadius > 0.f && cohesionStiffness >= 0.f, "cohesion radius must be positive, stiffness ≥ 0");
    check(adhesionWeight >= 0.f && adhesionRadius > 0.f, "adhesion weight must be ≥ 0, radius positive");
    check(globalStiffness > 0.f && globalStiffness <= 1.f && wetStiffness > 0.f && wetStiffness <= 1.f &&
              dryStiffness > 0.f && dryStiffness <= 1.f,
          "ξ, γ0, γ1 must be in (0, 1]");
    check(stiffnessStep > 0.f, "stiffness reference step must be positive");
    check(teleportDistance > 0.f && teleportAngle > 0.f, "teleport limits must be positive");
    check(strandsPerWorld >= 1 && threads >= 0, "strands per world must be ≥ 1, threads ≥ 0");
}

CurlyWetSettings CurlyWetSettings::resolved() const {
    CurlyWetSettings r = *this;
    const curly::MaterialSprings m = curly::materialSprings(material, curlRadius, curlPitch,
                                                            length / float(std::max(1, particles - 1)),
                                                            massPerLength, timeStep / float(std::max(1, substeps)));
    if (r.massPerLength < 0.f) r.massPerLength = m.massPerLength;
    if (r.stretchStiffness < 0.f) r.stretchStiffness = m.ks;
    if (r.bendStiffness < 0.f) r.bendStiffness = m.kb;
    if (r.coreStiffness < 0.f) r.coreStiffness = m.kc;
    if (r.helixWeight < 0.f) r.helixWeight = 5.f * r.bendStiffness;
    return r;
}

CurlyWetSettings CurlyWetSettings::seedSprings() {
    CurlyWetSettings s;
    s.massPerLength = 0.005f;
    s.stretchStiffness = 5000.f;
    s.bendStiffness = s.coreStiffness = 20.f;
    s.helixWeight = 100.f;
    return s;
}

struct CurlyWetSolver::Impl final : solver::StrandModel {
    CurlySet set;
    std::vector<std::unique_ptr<curly::CurlyWorld>> groups;
    std::vector<uint32_t> strandOf;
    curly::SpatialGrid grid;
    solver::Skeleton skeleton;
    // Counters of the current step.
    std::vector<curly::GroupCounters> counters;  ///< per group, of the last substep
    size_t failures = 0;
    double neighbours = 0;

    explicit Impl(const CurlyWetSettings& s) : skeleton(*this, set, "curly/wet solver", s) {
        set.settings = s;
    }

    void updateWet() {
        set.wet = false;
        if (!set.settings.wetEffects) return;
        for (size_t g = 0; g < set.count && !set.wet; ++g)
            for (int i = 1; i < set.n && !set.wet; ++i) set.wet = set.sigma[set.particle(g, i)] > 0.f;
    }

    /// Cohesion targets from the current (= previous step's) positions.
    /// Each particle's sum runs over its neighbours in a fixed order, so the
    /// result is the same whatever the thread count.
    double cohesionPass() {
        const CurlyWetSettings& s = set.settings;
        if (!set.wet || !s.cohesion || s.cohesionStiffness <= 0.f) {
            set.cohesion.clear();
            return 0.0;
        }
        const size_t total = set.x.size();
        set.cohesion.resize(total);
        grid.build(set.x.data(), strandOf.data(), total, s.cohesionRadius);
        skeleton.parallel(total, 1024, [&](size_t b, size_t e) {
            curly::cohesionTargets(grid, set.sigma.data(), b, e, s.cohesionRadius, s.cohesionTightness,
                                   set.cohesion.data());
        });
        size_t neighbours = 0;
        for (size_t g = 0; g < set.count; ++g) {
            set.cohesion[set.particle(g, 0)] = curly::CohesionTarget{};  // the kinematic root
            for (int i = 1; i < set.n; ++i) neighbours += set.cohesion[set.particle(g, i)].neighbours;
        }
        const size_t free = set.count * size_t(set.n - 1);
        return free ? double(neighbours) / double(free) : 0.0;
    }

    // solver::StrandModel: the curly guides' own step.
    void beginStep(const HeadPose&, bool cut) override {
        neighbours = cut ? 0.0 : cohesionPass();
        failures = 0;
        counters.assign(groups.size(), curly::GroupCounters{});
    }
    void resetToRest(const HeadPose&) override {
        for (size_t g = 0; g < set.count; ++g) set.resetGuide(g);
    }
    void substep(const solver::Substep& sub) override {
        skeleton.parallel(groups.size(), 1, [&](size_t b, size_t e) {
            for (size_t i = b; i < e; ++i) counters[i] = groups[i]->substep(sub);
        });
        for (const curly::GroupCounters& c : counters) failures += c.failed;
    }
    void endStep(bool, StepStats& c) override {
        for (const curly::GroupCounters& g : counters) c.adhesionCount += g.adhesion;
        c.implicitFailures = failures;
        c.meanCohesionNeighbours = neighbours;
    }
    StepStats measure(const Collider* collider) const override;
    /// Interpolated chords are shorter than the edges: restores each to the
    /// interpolated length, root to tip.
    void restoreLengths(size_t g, float a, Vec3f* x) const override {
        for (int i = 0; i + 1 < set.n; ++i) {
            const size_t k = set.particle(g, i);
            const float len0 = (set.xPrev[k + 1] - set.xPrev[k]).norm();
            const float len1 = (set.x[k + 1] - set.x[k]).norm();
            const float want = (1.f - a) * len0 + a * len1;
            const Vec3f e = x[i + 1] - x[i];
            const float len = e.norm();
            if (len > 1e-12f) x[i + 1] = x[i] + e * (want / len);
        }
    }
};

CurlyWetSolver::CurlyWetSolver(const CurlyWetSettings& settings) {
    settings.validate();
    impl_ = std::make_unique<Impl>(settings.resolved());
    skeleton_ = &impl_->skeleton;
}

CurlyWetSolver::~CurlyWetSolver() = default;

void CurlyWetSolver::initialize(const std::vector<SurfaceFrame>& roots, const HeadPose& head,
                                const std::vector<std::vector<Vec3f>>* groom) {
    Impl& m = *impl_;
    CurlySet& set = m.set;
    const CurlyWetSettings& s = set.settings;
    if (groom && groom->size() != roots.size())
        throw Error(cat("curly/wet solver: ", groom->size(), " groomed strands for ", roots.size(), " roots"));
    set.resize(roots, s.particles);
    set.n = s.particles;
    const int n = set.n;
    const size_t np = set.count * size_t(n), ne = set.count * size_t(n - 1);
    set.restLocal.assign(np, Vec3f::Zero());
    set.helix.assign(np, Vec3f::Zero());
    set.mass.assign(np, 0.f);
    set.edgeLength.assign(ne, 0.f);
    set.bendTarget.assign(ne, Vec3f::Zero());
    set.coreLength.assign(ne, 0.f);
    set.sigma.assign(np, 0.f);
    set.cohesion.clear();
    m.strandOf.resize(np);

    // Coefficients; β uses the mean rest edge length (Iben et al.'s l).
    curly::StrandCoefficients& k = set.coefficients;
    const float segment = s.length / float(n - 1);
    k.ks = s.stretchStiffness;
    k.cs = s.stretchDamping;
    k.kb = s.bendStiffness;
    k.cb = s.bendDamping;
    k.kc = s.coreStiffness;
    k.cc = s.coreDamping;
    k.betaBend = curly::smoothingBeta(segment, s.bendSmoothing);
    k.betaCore = curly::smoothingBeta(segment, s.coreSmoothing);
    k.curlWeight = s.helixWeight;
    k.cohesionStiffness = s.cohesion ? s.cohesionStiffness : 0.f;
    k.gravity = s.gravity;

    // Root-local coordinates: columns of rootFrame are (tangent, normal,
    // tangent × normal); a helix along +Z maps x → tangent, y → -(t × n),
    // z → normal (a proper rotation).
    auto fromHelix = [](const Vec3f& p) { return Vec3f(p.x(), p.z(), -p.y()); };
    std::vector<Vec3f> pts(n);
    const float wetRadius = s.helixRadius > 0.f ? s.helixRadius : s.curlRadius;
    const float wetPitch = s.helixPitch > 0.f ? s.helixPitch : s.curlPitch;
    for (size_t g = 0; g < set.count; ++g) {
        const Mat3f R = set.rootRot1[g].toRotationMatrix();
        Vec3f* local = &set.restLocal[set.particle(g, 0)];
        float strandLength = s.length;
        if (groom) {
            const std::vector<Vec3f>& p = (*groom)[g];
            if (p.size() != size_t(n))
                throw Error(cat("curly/wet solver: groomed strand ", g, " has ", p.size(), " particles, expected ", n));
            strandLength = 0.f;
            for (int i = 0; i < n; ++i) {
                local[i] = R.transpose() * (p[i] - set.rootPos1[g]);
                if (i > 0) {
                    const float len = (p[i] - p[i - 1]).norm();
                    if (!(len > 1e-7f))
                        throw Error(cat("curly/wet solver: groomed strand ", g, " has a zero-length edge ", i - 1));
                    strandLength += len;
                }
            }
        } else {
            curly::helixPoints(s.curlRadius, s.curlPitch, segment, size_t(n), pts.data());
            for (int i = 0; i < n; ++i) local[i] = fromHelix(pts[i]);
        }
        curly::helixPoints(wetRadius, wetPitch, strandLength / float(n - 1), size_t(n), pts.data());
        for (int i = 0; i < n; ++i) {
            set.helix[set.particle(g, i)] = fromHelix(pts[i]);
            m.strandOf[set.particle(g, i)] = uint32_t(g);
        }
        // Lumped masses: each particle carries half of its edges.
        float* mass = &set.mass[set.particle(g, 0)];
        for (int j = 0; j + 1 < n; ++j) {
            const float half = 0.5f * s.massPerLength * (local[j + 1] - local[j]).norm();
            mass[j] += half;
            mass[j + 1] += half;
        }
        // Rest data in root-local coordinates (root frame = identity there);
        // gravity rotated into them for the pre-load.
        curly::StrandCoefficients kl = k;
        kl.gravity = R.transpose() * s.gravity;
        curly::restData(local, size_t(n), Mat3f::Identity(), kl, mass, s.preload,
                        &set.edgeLength[set.edge(g, 0)], &set.bendTarget[set.edge(g, 0)],
                        &set.coreLength[set.edge(g, 0)]);
        set.resetGuide(g);
    }
    set.keepPrevious();
    setSaturation(s.saturation);

    m.groups.clear();
    const size_t perWorld = size_t(s.strandsPerWorld);
    for (size_t b = 0; b < set.count; b += perWorld)
        m.groups.push_back(curly::makeCurlyWorld(set, b, std::min(set.count, b + perWorld)));
    m.skeleton.start(head);
}

void CurlyWetSolver::setSaturation(float sigma) {
    CurlySet& set = impl_->set;
    const CurlyWetSettings& s = set.settings;
    if (!std::isfinite(sigma)) throw Error("curly/wet solver: saturation is not finite");
    for (size_t g = 0; g < set.count; ++g)
        for (int i = 0; i < set.n; ++i)
            set.sigma[set.particle(g, i)] =
                curly::saturationAt(sigma, s.saturationRoot, s.saturationTip, float(i) / float(set.n - 1));
    impl_->updateWet();
}

void CurlyWetSolver::setSaturation(const std::vector<float>& perParticle) {
    CurlySet& set = impl_->set;
    if (perParticle.size() != set.sigma.size())
        throw Error(cat("curly/wet solver: ", perParticle.size(), " saturations for ", set.sigma.size(), " particles"));
    for (size_t k = 0; k < perParticle.size(); ++k) {
        if (!std::isfinite(perParticle[k])) throw Error(cat("curly/wet solver: saturation ", k, " is not finite"));
        set.sigma[k] = std::clamp(perParticle[k], 0.f, 1.f);
    }
    impl_->updateWet();
}

const std::vector<float>& CurlyWetSolver::saturation() const { return impl_->set.sigma; }

StepStats CurlyWetSolver::Impl::measure(const Collider* collider) const {
    struct Partial {
        double maxErr = 0, sumErr = 0, maxDepth = 0, energy = 0, sigma = 0;
        size_t inside = 0, nan = 0;
    };
    const size_t perGroup = size_t(set.settings.strandsPerWorld);
    const size_t chunks = (set.count + perGroup - 1) / perGroup;
    std::vector<Partial> parts(chunks);
    auto body = [&](size_t c) {
        Partial& p = parts[c];
        for (size_t g = c * perGroup; g < std::min(set.count, (c + 1) * perGroup); ++g) {
            for (int j = 0; j + 1 < set.n; ++j) {
                const double len = (set.x[set.particle(g, j + 1)] - set.x[set.particle(g, j)]).norm();
                const double e = std::abs(len / set.edgeLength[set.edge(g, j)] - 1.0);
                p.maxErr = std::max(p.maxErr, e);
                p.sumErr += e;
            }
            for (int i = 0; i < set.n; ++i) {
                const size_t k = set.particle(g, i);
                if (!set.x[k].allFinite() || !set.v[k].allFinite()) ++p.nan;
                if (i == 0) continue;  // the root sits on the scalp by definition
                p.energy += 0.5 * set.mass[k] * set.v[k].squaredNorm();
                p.sigma += set.settings.wetEffects ? set.sigma[k] : 0.f;
                if (collider) {
                    const float d = collider->signedDistance(set.x[k]);
                    if (d < 0.f) {
                        ++p.inside;
                        p.maxDepth = std::max(p.maxDepth, double(-d));
                    }
                }
            }
        }
    };
    skeleton.parallel(chunks, 1, [&](size_t b, size_t e) {
        for (size_t c = b; c != e; ++c) body(c);
    });
    StepStats s;
    double sumErr = 0, sumSigma = 0;
    for (const Partial& p : parts) {  // fixed order: same sums whatever the threads
        s.maxLengthError = std::max(s.maxLengthError, p.maxErr);
        sumErr += p.sumErr;
        s.maxPenetration = std::max(s.maxPenetration, p.maxDepth);
        s.penetrationCount += p.inside;
        s.nanCount += p.nan;
        s.kineticEnergy += p.energy;
        sumSigma += p.sigma;
    }
    const size_t edges = set.count * size_t(set.n - 1);
    s.meanLengthError = edges ? sumErr / double(edges) : 0.0;
    s.meanSaturation = edges ? sumSigma / double(edges) : 0.0;
    return s;
}

std::vector<char> CurlyWetSolver::saveState() const {
    const Impl& m = *impl_;
    const CurlySet& set = m.set;
    BlobWriter w;
    m.skeleton.saveClock(w);
    set.save(w);
    w.array(set.sigma);
    return std::move(w.data);
}

void CurlyWetSolver::restoreState(const std::vector<char>& state) {
    Impl& m = *impl_;
    CurlySet& set = m.set;
    m.skeleton.requireStarted("restoreState()");
    BlobReader r(state, "curly/wet solver");
    m.skeleton.restoreClock(r);
    set.restore(r);
    r.array(set.sigma, set.count * size_t(set.n));
    r.finish();
    m.updateWet();
}
int CurlyWetSolver::particlesPerGuide() const { return impl_->set.n; }
const CurlyWetSettings& CurlyWetSolver::settings() const { return impl_->set.settings; }
StepStats CurlyWetSolver::measure(const Collider* collider) const { return impl_->measure(collider); }

Eigen::Vector2f CurlyWetSolver::measureCurl(size_t skip) const {
    const CurlySet& set = impl_->set;
    std::vector<float> radii, pitches;
    for (size_t g = 0; g < set.count; ++g) {
        const curly::HelixFit f = curly::fitHelix(&set.x[set.particle(g, 0)], size_t(set.n), skip);
        if (f.samples == 0) continue;
        radii.push_back(f.radius);
        pitches.push_back(f.pitch);
    }
    if (radii.empty()) return Eigen::Vector2f::Zero();
    auto median = [](std::vector<float>& v) {
        std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
        return v[v.size() / 2];
    };
    return Eigen::Vector2f(median(radii), median(pitches));
}

}  // namespace hp
