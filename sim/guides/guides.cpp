// GuideSolver: rest shapes, the step loop (substeps, teleports, strand-strand
// contacts), parallelism over Bullet worlds, statistics. The Bullet side of
// each formulation is in sim/guides/rope_group.cpp and sim/guides/rigid_group.cpp.
#include "sim/guides/guides.h"
#include "sim/solver/scene_cut.h"
#include "sim/solver/state_blob.h"

#include "core/errors.h"
#include "sim/guides/guide_group.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

namespace hp {

using guides::GuideSet;
using strand::Mat3f;
using strand::Quatf;

const char* formulationName(GuideFormulation f) {
    return f == GuideFormulation::Rigid ? "rigid" : f == GuideFormulation::Rod ? "rod" : "rope";
}

GuideFormulation parseFormulation(const std::string& name) {
    if (name == "rope") return GuideFormulation::Rope;
    if (name == "rigid") return GuideFormulation::Rigid;
    if (name == "rod") return GuideFormulation::Rod;
    throw Error(cat("unknown guide formulation '", name, "' (choices: rod, rope, rigid)"));
}

void GuideSettings::validate() const {
    auto check = [](bool ok, const char* what) {
        if (!ok) throw Error(cat("guide settings: ", what));
    };
    check(segments >= 1 && segments <= 1000, "segments must be in [1, 1000]");
    check(length > 0.f, "length must be positive");
    check(collisionRadius >= 0.f, "collision radius must be ≥ 0");
    check(timeStep > 0.f, "time step must be positive");
    check(substeps >= 1, "substeps must be ≥ 1");
    check(iterations >= 1, "iterations must be ≥ 1");
    check(massPerLength > 0.f, "mass per length must be positive");
    check(bendStiffness >= 0.f && limitStiffness >= 0.f && bendDamping >= 0.f, "stiffness and damping must be ≥ 0");
    check(damping >= 0.f, "damping must be ≥ 0");
    check(youngsModulus >= 0.f && shearModulus >= 0.f, "Young's and shear moduli must be ≥ 0");
    check(density > 0.f && hairsPerGuide > 0.f, "density and hairs per guide must be positive");
    check(formulation != GuideFormulation::Rod || rootRadius > 0.f, "the rod needs a fibre radius (root radius) > 0");
    check(rodSubsteps >= 1, "rod substeps must be ≥ 1");
    check(friction >= 0.f, "friction must be ≥ 0");
    check(bendLimit > 0.f && bendLimit < 180.f, "bend limit must be in (0, 180) degrees");
    check(twistLimit > 0.f && twistLimit < 90.f, "twist limit must be in (0, 90) degrees");
    check(projectionAngle >= 0.f && projectionDistance >= 0.f, "projection limits must be ≥ 0");
    check(maxSpeed >= 0.f, "max speed must be ≥ 0");
    check(strandsPerWorld >= 1, "strands per world must be ≥ 1");
    check(threads >= 0, "threads must be ≥ 0");
    check(gravity.allFinite(), "gravity must be finite");
}

void GuideStats::accumulate(const GuideStats& s) {
    maxLengthError = std::max(maxLengthError, s.maxLengthError);
    meanLengthError = std::max(meanLengthError, s.meanLengthError);
    penetrationCount = std::max(penetrationCount, s.penetrationCount);
    maxPenetration = std::max(maxPenetration, s.maxPenetration);
    kineticEnergy = s.kineticEnergy;
    nanCount += s.nanCount;
    if (firstNonFinite < 0) firstNonFinite = s.firstNonFinite;
    clampedCount += s.clampedCount;
    pinnedCount = std::max(pinnedCount, s.pinnedCount);
    strandContacts = std::max(strandContacts, s.strandContacts);
    msPerStep = (msPerStep * double(steps) + s.msPerStep * double(s.steps)) / double(steps + s.steps);
    steps += s.steps;
    reset = reset || s.reset;
}

std::string GuideStats::json(int frame, double time) const {
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "{\"frame\": %d, \"time\": %.6f, \"max_length_error\": %.3e, \"mean_length_error\": %.3e, "
                  "\"penetrations\": %zu, \"max_penetration_m\": %.3e, \"kinetic_energy_j\": %.6e, "
                  "\"nan\": %zu, \"clamped\": %zu, \"pinned\": %zu, \"strand_contacts\": %zu, \"ms_per_step\": %.3f, "
                  "\"steps\": %zu, \"reset\": %s}",
                  frame, time, maxLengthError, meanLengthError, penetrationCount, maxPenetration, kineticEnergy,
                  nanCount, clampedCount, pinnedCount, strandContacts, msPerStep, steps, reset ? "true" : "false");
    return buf;
}

namespace guides {

void GuideSet::restShape(size_t g, const Vec3f& p, const Mat3f& R, Vec3f* out) const {
    out[0] = p;
    for (int j = 0; j < segments; ++j)
        out[j + 1] = out[j] + R * (restLength[segment(g, j)] * groomDir[segment(g, j)]);
}

void GuideSet::resetGuides(size_t begin, size_t end) {
    for (size_t g = begin; g < end; ++g) {
        restShape(g, rootPos1[g], rootRot1[g].toRotationMatrix(), &x[vertex(g, 0)]);
        for (int i = 0; i < vertices; ++i) v[vertex(g, i)] = Vec3f::Zero();
    }
}

double GuideSet::kineticEnergy(size_t begin, size_t end) const {
    double e = 0;
    for (size_t g = begin; g < end; ++g)
        for (int i = 1; i < vertices; ++i) {
            const size_t k = vertex(g, i);
            e += 0.5 * mass[k] * v[k].squaredNorm();
        }
    return e;
}

float GuideSet::maxBend(size_t begin, size_t end) const {
    float bend = 0.f;
    for (size_t g = begin; g < end; ++g) bend = std::max(bend, maxBendAngle(*this, g, &x[vertex(g, 0)], rootRot1[g]));
    return bend;
}

float maxBendAngle(const GuideSet& set, size_t g, const Vec3f* x, const Quatf& rootRot) {
    Mat3f Q = rootRot.toRotationMatrix();
    float worst = 0.f;
    for (int j = 0; j < set.segments; ++j) {
        const Vec3f rest = Q * set.groomDir[set.segment(g, j)];
        const Vec3f d = (x[j + 1] - x[j]).normalized();
        worst = std::max(worst, strand::angleBetween(d, rest));
        Q = strand::transport(rest, d) * Q;
    }
    return worst;
}

}  // namespace guides

struct GuideSolver::Impl {
    GuideSet set;
    std::unique_ptr<guides::Formulation> formulation;
    std::vector<std::unique_ptr<guides::GuideGroup>> groups;
    std::unique_ptr<guides::StrandContacts> contacts;
    std::unique_ptr<tbb::task_arena> arena;
    double time = 0, prevTime = 0;
    double startTime = 0;  ///< head.time at initialize
    long steps = 0;        ///< steps since; time = startTime + steps·timeStep (no drift)
    Eigen::Isometry3f headTransform = Eigen::Isometry3f::Identity();
    GuideStats last;
    bool initialized = false;

    template <typename F>
    void forGroups(F&& f) {
        auto loop = [&] {
            tbb::parallel_for(
                tbb::blocked_range<size_t>(0, groups.size(), 1),
                [&](const tbb::blocked_range<size_t>& r) {
                    for (size_t i = r.begin(); i != r.end(); ++i) f(*groups[i]);
                },
                tbb::simple_partitioner());
        };
        if (arena) arena->execute(loop);
        else loop();
    }

    void setRoots(const std::vector<SurfaceFrame>& roots, bool start) {
        for (size_t g = 0; g < set.count; ++g) {
            set.rootPos1[g] = roots[g].position;
            set.rootRot1[g] = Quatf(strand::rootRotation(roots[g]));
            if (start) {
                set.rootPos0[g] = set.rootPos1[g];
                set.rootRot0[g] = set.rootRot1[g];
            }
        }
    }

    /// Lengths and head clearance of one guide after strand-strand pushes.
    void relax(size_t g, const strand::HeadQuery* head) {
        Vec3f* x = &set.x[set.vertex(g, 0)];
        for (int j = 0; j < set.segments; ++j)
            strand::placeSegment(x[j], x[j + 1], set.restLength[set.segment(g, j)], head,
                                 set.settings.collisionRadius);
    }

    GuideStats measure(const Collider* collider) const;
};

GuideSolver::GuideSolver(const GuideSettings& settings) : impl_(std::make_unique<Impl>()) {
    settings.validate();
    impl_->set.settings = settings;
    if (settings.threads > 0) impl_->arena = std::make_unique<tbb::task_arena>(settings.threads);
}

GuideSolver::~GuideSolver() = default;

void GuideSolver::initialize(const std::vector<SurfaceFrame>& roots, const HeadPose& head,
                             const std::vector<std::vector<Vec3f>>* groom) {
    Impl& m = *impl_;
    GuideSet& set = m.set;
    const GuideSettings& s = set.settings;
    set.count = roots.size();
    set.segments = s.segments;
    set.vertices = s.segments + 1;
    if (groom && groom->size() != roots.size())
        throw Error(cat("guide solver: ", groom->size(), " groomed strands for ", roots.size(), " roots"));
    const size_t nv = set.count * set.vertices, ns = set.count * set.segments;
    set.restLength.assign(ns, s.length / float(s.segments));
    set.groomDir.assign(ns, Vec3f::UnitY());
    set.springDir.assign(ns, Vec3f::UnitY());
    set.spring.assign(ns, 0.f);
    set.limitSpring.assign(ns, 0.f);
    set.limitPerIteration.assign(ns, 0.f);
    set.minSpan.assign(ns, 0.f);
    set.maxSpan.assign(ns, 0.f);
    set.jointInertia.assign(ns, 0.f);
    set.restBend.assign(ns, 0.f);
    set.cosMostBend.assign(ns, 0.f);
    set.cosLeastBend.assign(ns, 0.f);
    set.mass.assign(nv, 0.f);
    set.x.assign(nv, Vec3f::Zero());
    set.v.assign(nv, Vec3f::Zero());
    set.rootPos0.resize(set.count);
    set.rootPos1.resize(set.count);
    set.rootRot0.resize(set.count);
    set.rootRot1.resize(set.count);
    m.setRoots(roots, true);

    for (size_t g = 0; g < set.count; ++g) {
        const Mat3f R = set.rootRot1[g].toRotationMatrix();
        if (groom) {
            const std::vector<Vec3f>& strandPts = (*groom)[g];
            if (strandPts.size() != size_t(set.vertices))
                throw Error(cat("guide solver: groomed strand ", g, " has ", strandPts.size(), " vertices, expected ",
                                set.vertices));
            for (int j = 0; j < set.segments; ++j) {
                const Vec3f e = R.transpose() * (strandPts[j + 1] - strandPts[j]);
                const float len = e.norm();
                if (!(len > 1e-7f)) throw Error(cat("guide solver: groomed strand ", g, " has a zero-length segment ", j));
                set.restLength[set.segment(g, j)] = len;
                set.groomDir[set.segment(g, j)] = e / len;
            }
        }
        // Lumped masses: each vertex carries half of its two segments.
        const float mu =
            s.formulation == GuideFormulation::Rod ? float(guides::rodMassPerLength(s)) : s.massPerLength;
        for (int j = 0; j < set.segments; ++j) {
            const float half = 0.5f * mu * set.restLength[set.segment(g, j)];
            if (j > 0) set.mass[set.vertex(g, j)] += half;
            set.mass[set.vertex(g, j + 1)] += half;
        }
        for (int j = 0; j < set.segments; ++j) {
            const size_t seg = set.segment(g, j);
            // The joint drive acts on its own segment (inertia m·l² about the
            // joint); what hangs beyond is carried along (strand::relaxJoints).
            const float inertia = set.mass[set.vertex(g, j + 1)] * set.restLength[seg] * set.restLength[seg];
            set.jointInertia[seg] = inertia;
            set.springDir[seg] = set.groomDir[seg];
            const float h = s.timeStep / float(s.substeps);
            set.spring[seg] = strand::springFraction(s.bendStiffness, inertia, h);
            set.limitSpring[seg] = strand::springFraction(s.limitStiffness, inertia, h);
            // Spread over the limit checks inside Bullet's link iterations (one per 4).
            const int checks = (s.iterations + 3) / 4;
            set.limitPerIteration[seg] = 1.f - std::pow(1.f - set.limitSpring[seg], 1.f / float(checks));
        }
        strand::bendBounds(&set.groomDir[set.segment(g, 0)], set.segments,
                           (s.bendLimit + s.projectionAngle) * float(M_PI / 180.0), &set.restBend[set.segment(g, 0)],
                           &set.cosMostBend[set.segment(g, 0)], &set.cosLeastBend[set.segment(g, 0)]);
        strand::bendLimitSpan(&set.restLength[set.segment(g, 0)], &set.groomDir[set.segment(g, 0)], set.segments,
                              s.bendLimit * float(M_PI / 180.0), &set.minSpan[set.segment(g, 0)],
                              &set.maxSpan[set.segment(g, 0)]);
        set.restShape(g, set.rootPos1[g], R, &set.x[set.vertex(g, 0)]);
    }
    set.xPrev = set.x;
    set.vPrev = set.v;

    set.headTransform = head.transform;
    m.formulation = s.formulation == GuideFormulation::Rigid ? guides::makeRigidFormulation(set, head)
                    : s.formulation == GuideFormulation::Rod ? guides::makeRodFormulation()
                                                             : guides::makeRopeFormulation(set);
    const size_t perWorld =
        s.formulation == GuideFormulation::Rigid && s.strandCollision ? set.count : size_t(s.strandsPerWorld);
    m.groups.clear();
    for (size_t b = 0; b < set.count; b += perWorld)
        m.groups.push_back(m.formulation->makeGroup(set, b, std::min(set.count, b + perWorld)));
    m.contacts.reset();
    if (s.strandCollision && s.formulation != GuideFormulation::Rigid)
        m.contacts = std::make_unique<guides::StrandContacts>(set);

    ++set.version;
    if (s.preload) {
        guides::SubstepContext ctx;
        ctx.h = s.timeStep / float(s.substeps);
        ctx.headTransform = head.transform;
        ctx.headCollision = false;
        m.forGroups([&](guides::GuideGroup& grp) { grp.preload(ctx); });
    }
    m.time = m.prevTime = m.startTime = head.time;
    m.steps = 0;
    m.headTransform = head.transform;
    m.last = GuideStats{};
    m.initialized = true;
}

const GuideStats& GuideSolver::step(const std::vector<SurfaceFrame>& roots, const HeadPose& head) {
    Impl& m = *impl_;
    GuideSet& set = m.set;
    const GuideSettings& s = set.settings;
    if (!m.initialized) throw Error("guide solver: step() before initialize()");
    if (roots.size() != set.count)
        throw Error(cat("guide solver: ", roots.size(), " root frames for ", set.count, " guides"));
    const double expected = m.startTime + double(m.steps + 1) * double(s.timeStep);
    if (std::abs(head.time - expected) > 1e-6 * std::max(1.0, std::abs(expected)))
        throw Error(cat("guide solver: head pose at t = ", head.time, " s, expected the step's end t = ", expected,
                        " s"));
    const auto clock0 = std::chrono::steady_clock::now();
    m.setRoots(roots, false);
    set.xPrev = set.x;
    set.vPrev = set.v;

    // A scene cut or teleport: the head or a root jumps further in one step
    // than the limits allow. The guides restart at rest on the new roots.
    const Eigen::Isometry3f& T0 = m.headTransform;
    const Eigen::Isometry3f& T1 = head.transform;
    float rootJump = 0.f;
    for (size_t g = 0; g < set.count; ++g) rootJump = std::max(rootJump, (set.rootPos1[g] - set.rootPos0[g]).norm());
    const bool teleport = isCut(stepJump(T0, T1, rootJump), s.teleportDistance, s.teleportAngle);
    size_t strandContacts = 0;
    set.headTransform = T1;
    if (teleport) {
        m.forGroups([](guides::GuideGroup& grp) { grp.reset(); });
        // The rest shape on the new pose may cross the head or another
        // collider (the new pose is arbitrary): place it outside every one
        // before the cut frame is written, lengths kept (strand::placeSegment).
        if (s.headCollision && head.collider) {
            strand::HeadQuery hq;
            hq.collider = head.collider.get();
            m.forGroups([&](guides::GuideGroup& grp) {
                for (size_t g = grp.begin(); g < grp.end(); ++g) m.relax(g, &hq);
            });
        }
        ++set.version;
        set.xPrev = set.x;
        set.vPrev = set.v;
    } else {
        m.formulation->beginStep(head);
        const Quatf q0(T0.linear()), q1(T1.linear());
        auto headAt = [&](float a) {
            Eigen::Isometry3f t = Eigen::Isometry3f::Identity();
            t.linear() = q0.slerp(a, q1).toRotationMatrix();
            t.translation() = (1.f - a) * T0.translation() + a * T1.translation();
            return t;
        };
        for (int k = 0; k < s.substeps; ++k) {
            guides::SubstepContext ctx;
            ctx.h = s.timeStep / float(s.substeps);
            ctx.alpha = float(k + 1) / float(s.substeps);
            ctx.headTransform = headAt(ctx.alpha);
            const Eigen::Isometry3f prev = headAt(float(k) / float(s.substeps));
            ctx.head.collider = head.collider.get();
            ctx.head.toCollider = T1 * ctx.headTransform.inverse();
            ctx.head.normalToWorld = ctx.headTransform.linear() * T1.linear().transpose();
            ctx.head.toPrevious = prev * ctx.headTransform.inverse();
            ctx.headCollision = s.headCollision;
            m.forGroups([&](guides::GuideGroup& grp) { grp.substep(ctx); });
            if (m.contacts) {
                const strand::HeadQuery* hq = ctx.headCollision && ctx.head.collider ? &ctx.head : nullptr;
                strandContacts += m.contacts->solve(set, ctx.h, [&](size_t g) { m.relax(g, hq); });
                ++set.version;
            }
        }
    }
    // Velocity guard (GuideSettings::maxSpeed). A NaN speed fails the
    // comparison and is left for measure() to report. Rod and rope only: their groups
    // reload x / v from the set when the version moves, while the rigid
    // formulation's bodies keep their own state (set.v is a read-back).
    size_t clamped = 0;
    if (s.maxSpeed > 0.f && !teleport && s.formulation != GuideFormulation::Rigid) {
        for (Vec3f& v : set.v) {
            const float speed = v.norm();
            if (speed > s.maxSpeed) {
                v *= s.maxSpeed / speed;
                ++clamped;
            }
        }
        if (clamped) ++set.version;  // the groups reload the clamped state
    }
    for (size_t g = 0; g < set.count; ++g) {
        set.rootPos0[g] = set.rootPos1[g];
        set.rootRot0[g] = set.rootRot1[g];
    }
    m.headTransform = head.transform;
    m.prevTime = m.time;
    m.time = expected;
    ++m.steps;

    m.last = m.measure(head.collider.get());
    m.last.reset = teleport;
    m.last.strandContacts = strandContacts;
    m.last.clampedCount = clamped;
    for (auto& grp : m.groups) m.last.pinnedCount += grp->takePinned();
    m.last.msPerStep =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - clock0).count();
    return m.last;
}

GuideStats GuideSolver::Impl::measure(const Collider* collider) const {
    struct Partial {
        double maxErr = 0, sumErr = 0, maxDepth = 0, energy = 0;
        size_t inside = 0, nan = 0;
        long firstNan = -1;
    };
    std::vector<Partial> parts(groups.size());
    auto body = [&](size_t gi) {
        Partial& p = parts[gi];
        const guides::GuideGroup& grp = *groups[gi];
        for (size_t g = grp.begin(); g < grp.end(); ++g) {
            for (int j = 0; j < set.segments; ++j) {
                const float e =
                    strand::stretch(set.x[set.vertex(g, j)], set.x[set.vertex(g, j + 1)], set.restLength[set.segment(g, j)]);
                p.maxErr = std::max(p.maxErr, double(e));
                p.sumErr += e;
            }
            for (int i = 0; i < set.vertices; ++i) {
                const size_t k = set.vertex(g, i);
                if (!set.x[k].allFinite() || !set.v[k].allFinite()) {
                    ++p.nan;
                    if (p.firstNan < 0) p.firstNan = long(g);
                }
                // The root sits on the scalp by definition; only the free vertices count.
                if (i > 0 && collider) {
                    const float d = collider->signedDistance(set.x[k]);
                    if (d < 0.f) {
                        ++p.inside;
                        p.maxDepth = std::max(p.maxDepth, double(-d));
                    }
                }
            }
        }
        p.energy = grp.kineticEnergy();
    };
    auto loop = [&] {
        tbb::parallel_for(size_t(0), groups.size(), body);
    };
    if (arena) arena->execute(loop);
    else loop();
    GuideStats s;
    double sum = 0;
    for (const Partial& p : parts) {  // fixed order: same sums whatever the threads
        s.maxLengthError = std::max(s.maxLengthError, p.maxErr);
        sum += p.sumErr;
        s.maxPenetration = std::max(s.maxPenetration, p.maxDepth);
        s.penetrationCount += p.inside;
        s.nanCount += p.nan;
        if (s.firstNonFinite < 0) s.firstNonFinite = p.firstNan;  // groups in guide order
        s.kineticEnergy += p.energy;
    }
    const size_t segs = set.count * size_t(set.segments);
    s.meanLengthError = segs ? sum / double(segs) : 0.0;
    return s;
}

void GuideSolver::write(StrandFrame& frame) const { write(frame, impl_->time); }

void GuideSolver::write(StrandFrame& frame, double time) const {
    const Impl& m = *impl_;
    const GuideSet& set = m.set;
    const double span = m.time - m.prevTime;
    if (time < m.prevTime - 1e-9 || time > m.time + 1e-9)
        throw Error(cat("guide solver: cannot write t = ", time, " s; the last step covers [", m.prevTime, ", ", m.time,
                        "] s"));
    const float a = span > 0 ? float(std::clamp((time - m.prevTime) / span, 0.0, 1.0)) : 1.f;
    frame.clear();
    frame.time = time;
    frame.reserve(set.count, set.vertices);
    std::vector<Vec3f> x(set.vertices), v(set.vertices);
    std::vector<float> r(set.vertices);
    const GuideSettings& s = set.settings;
    for (int i = 0; i < set.vertices; ++i)
        r[i] = taperedRadius(s.rootRadius, s.tipRadius, float(i) / float(set.segments));
    for (size_t g = 0; g < set.count; ++g) {
        for (int i = 0; i < set.vertices; ++i) {
            const size_t k = set.vertex(g, i);
            x[i] = (1.f - a) * set.xPrev[k] + a * set.x[k];
            v[i] = (1.f - a) * set.vPrev[k] + a * set.v[k];
        }
        // Interpolated chords are shorter than the segments: restore lengths.
        if (a < 1.f) strand::followTheLeader(x.data(), &set.restLength[set.segment(g, 0)], set.vertices);
        frame.addStrand(uint32_t(g), x.data(), r.data(), x.size(), v.data());
    }
    frame.guideCount = uint32_t(set.count);
}

std::vector<char> GuideSolver::saveState() const {
    const Impl& m = *impl_;
    const GuideSet& set = m.set;
    if (set.settings.formulation == GuideFormulation::Rigid)
        throw Error("guide solver: checkpoints need the rod or rope formulation (the rigid one keeps state inside Bullet)");
    BlobWriter w;
    w.put(m.time);
    w.put(m.prevTime);
    w.put(m.startTime);
    w.put(m.steps);
    w.put(m.headTransform.matrix());
    w.put(set.headTransform.matrix());
    w.array(set.x);
    w.array(set.v);
    w.array(set.xPrev);
    w.array(set.vPrev);
    w.array(set.rootPos0);
    w.array(set.rootPos1);
    w.array(set.rootRot0);
    w.array(set.rootRot1);
    return std::move(w.data);
}

void GuideSolver::restoreState(const std::vector<char>& state) {
    Impl& m = *impl_;
    GuideSet& set = m.set;
    if (!m.initialized) throw Error("guide solver: restoreState() before initialize()");
    if (set.settings.formulation == GuideFormulation::Rigid)
        throw Error("guide solver: checkpoints need the rod or rope formulation");
    BlobReader r(state, "guide solver");
    m.time = r.get<double>();
    m.prevTime = r.get<double>();
    m.startTime = r.get<double>();
    m.steps = r.get<long>();
    m.headTransform.matrix() = r.get<Eigen::Matrix4f>();
    set.headTransform.matrix() = r.get<Eigen::Matrix4f>();
    const size_t vertices = set.count * size_t(set.vertices);
    r.array(set.x, vertices);
    r.array(set.v, vertices);
    r.array(set.xPrev, vertices);
    r.array(set.vPrev, vertices);
    r.array(set.rootPos0, set.count);
    r.array(set.rootPos1, set.count);
    r.array(set.rootRot0, set.count);
    r.array(set.rootRot1, set.count);
    r.finish();
    // The Bullet nodes of every world reload x and v before the next step:
    // a rope node's whole state is its position and velocity.
    ++set.version;
}

double GuideSolver::time() const { return impl_->time; }
double GuideSolver::nextTime() const {
    return impl_->startTime + double(impl_->steps + 1) * double(impl_->set.settings.timeStep);
}
size_t GuideSolver::guideCount() const { return impl_->set.count; }
const GuideSettings& GuideSolver::settings() const { return impl_->set.settings; }
const GuideStats& GuideSolver::lastStats() const { return impl_->last; }
GuideStats GuideSolver::measure(const Collider* collider) const { return impl_->measure(collider); }

void GuideSolver::jointAngles(float& maxBend, float& maxTwist) const {
    maxBend = maxTwist = 0.f;
    for (const auto& grp : impl_->groups) {
        float b, t;
        grp->jointAngles(b, t);
        maxBend = std::max(maxBend, b);
        maxTwist = std::max(maxTwist, t);
    }
    maxBend *= float(180.0 / M_PI);
    maxTwist *= float(180.0 / M_PI);
}

}  // namespace hp
