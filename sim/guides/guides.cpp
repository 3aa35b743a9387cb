// GuideSolver: rest shapes and the guides' own step (substeps over the
// formulation's groups, strand-strand contacts, the velocity guard) plugged
// into the solver skeleton (sim/solver/skeleton.h: time, head
// interpolation, scene cuts, written frames, statistics), parallelism over
// the groups. The Bullet side of each formulation is in
// sim/guides/rope_group.cpp and sim/guides/rigid_group.cpp.
#include "sim/guides/guides.h"

#include "core/errors.h"
#include "sim/guides/guide_group.h"
#include "sim/solver/skeleton.h"
#include "sim/volume/hair_grid.h"
#include "sim/volume/wisp_contact.h"

#include <algorithm>
#include <cmath>

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

const char* rodIntegratorName(RodIntegrator i) { return i == RodIntegrator::Euler ? "euler" : "bdf2"; }

RodIntegrator parseRodIntegrator(const std::string& name) {
    if (name == "bdf2") return RodIntegrator::Bdf2;
    if (name == "euler") return RodIntegrator::Euler;
    throw Error(cat("unknown rod integrator '", name, "' (choices: bdf2, euler)"));
}

double GuideSettings::guideMassPerLength() const {
    return formulation == GuideFormulation::Rod ? guides::rodMassPerLength(*this) : double(massPerLength);
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
    check(youngsModulus >= 0.f, "Young's modulus must be ≥ 0");
    check(density > 0.f && hairsPerGuide > 0.f, "density and hairs per guide must be positive");
    check(formulation != GuideFormulation::Rod || rootRadius > 0.f, "the rod needs a fibre radius (root radius) > 0");
    check(rodSubsteps >= 1, "rod substeps must be ≥ 1");
    check(preloadProbes >= 0, "pre-load probes must be ≥ 0");
    check(preloadReach >= 0.f, "pre-load reach must be ≥ 0");
    check(preloadLimit >= 0.f, "pre-load limit must be ≥ 0");
    check(friction >= 0.f, "friction must be ≥ 0");
    check(bendLimit > 0.f && bendLimit < 180.f, "bend limit must be in (0, 180) degrees");
    check(twistLimit > 0.f && twistLimit < 90.f, "twist limit must be in (0, 90) degrees");
    check(projectionAngle >= 0.f && projectionDistance >= 0.f, "projection limits must be ≥ 0");
    check(maxSpeed >= 0.f, "max speed must be ≥ 0");
    check(strandsPerWorld >= 1, "strands per world must be ≥ 1");
    check(threads >= 0, "threads must be ≥ 0");
    check(gravity.allFinite(), "gravity must be finite");
    volume.validate();
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

struct GuideSolver::Impl final : solver::StrandModel {
    GuideSet set;
    std::unique_ptr<guides::Formulation> formulation;
    std::vector<std::unique_ptr<guides::GuideGroup>> groups;
    std::unique_ptr<guides::StrandContacts> contacts;
    std::unique_ptr<volume::HairGrid> grid;  ///< hair against hair (null: off)
    std::unique_ptr<volume::WispContact> wisps;  ///< wisps against wisps (null: off)
    std::vector<Vec3f> substepStart, beforeWisps;  ///< the wisp contact's scratch
    solver::Skeleton skeleton;
    size_t strandContacts = 0;  ///< of the current step
    std::vector<Vec3f> beforePush;  ///< set.x before the grid's volume push (GuideGroup::displaced)
    volume::GridStats gridStats;  ///< of the current step: densest node, vertex pushes (summed over substeps)

    explicit Impl(const GuideSettings& s) : skeleton(*this, set, "guide solver", s) {
        set.settings = s;
    }

    template <typename F>
    void forGroups(F&& f) {
        skeleton.parallel(groups.size(), 1, [&](size_t b, size_t e) {
            for (size_t i = b; i != e; ++i) f(*groups[i]);
        });
    }

    /// Lengths and head clearance of one guide after strand-strand pushes.
    void relax(size_t g, const strand::HeadQuery* head) {
        Vec3f* x = &set.x[set.vertex(g, 0)];
        strand::HeadQuery own;
        if (head) {
            own = *head;
            own.ignoreParts = set.ignoredParts(g);
        }
        for (int j = 0; j < set.segments; ++j)
            strand::placeSegment(x[j], x[j + 1], set.restLength[set.segment(g, j)], head ? &own : nullptr,
                                 set.settings.collisionRadius);
    }

    /// relax(g, nullptr) on guides [b, e): lengths restored root to tip
    /// (follow the leader), the same moves, four guides interleaved: each
    /// guide is a chain of dependent square roots and divisions, and
    /// independent guides between them keep the divider busy.
    void restoreLengths(size_t b, size_t e) {
        // strand::followTheLeader's move, inline here so that the four
        // guides' square roots and divisions overlap (the same operations,
        // so the same bits).
        auto place = [](const Vec3f& parent, const Vec3f& child, float length) {
            const Vec3f d = child - parent;
            const float len = d.norm();
            return len > 1e-12f ? Vec3f(parent + d * (length / len)) : Vec3f(parent + Vec3f::UnitY() * length);
        };
        constexpr size_t kInterleave = 4;
        for (size_t g0 = b; g0 < e; g0 += kInterleave) {
            const size_t lanes = std::min(kInterleave, e - g0);
            for (int j = 0; j < set.segments; ++j)
                for (size_t l = 0; l < lanes; ++l) {
                    Vec3f* x = &set.x[set.vertex(g0 + l, 0)];
                    x[j + 1] = place(x[j], x[j + 1], set.restLength[set.segment(g0 + l, j)]);
                }
        }
    }

    /// Hair against hair: the grid's friction and volume on the state the
    /// substep starts from (sim/volume/hair_grid.h), the pushed guides'
    /// lengths restored at once; the formulation's step then restores
    /// clearance and computes velocities from positions, so the volume push
    /// adds no velocity.
    void couple(const solver::Substep& sub) {
        beforePush.resize(set.x.size());  // filled by the grid's first pass over x
        volume::GridInput in;
        in.x = set.x.data();
        in.v = set.v.data();
        in.mass = set.mass.data();
        in.count = set.x.size();
        in.lengthPerMass = float(double(set.settings.hairsPerGuide) / set.settings.guideMassPerLength());
        in.head = sub.headTransform;
        in.h = sub.h;
        in.before = beforePush.data();
        const volume::GridStats st = grid->apply(in, [&](size_t count, const std::function<void(size_t, size_t)>& f) {
            skeleton.parallel(count, std::max<size_t>(1, count / 64), f);
        });
        gridStats.maxDensity = std::max(gridStats.maxDensity, st.maxDensity);
        gridStats.pushed += st.pushed;
        if (st.pushed) {
            // The push moves vertices, not segments: restore the lengths it
            // changed here, at position level, so that the whole move is
            // displacement (the rod's BDF2 history moves with it). Left to
            // the formulation's step, the correction was motion within the
            // step and became velocity: the crossing wisps under BDF2 gained
            // 149% / 162% of the energy their fall releases at 2 / 4
            // substeps, 2% / 4% with it (tests/test_hair_grid.cpp). Lengths
            // only: the step restores the head's clearance.
            forGroups([&](guides::GuideGroup& grp) {
                restoreLengths(grp.begin(), grp.end());
                grp.displaced(beforePush.data());  // reads and moves only this group's vertices
            });
        }
        ++set.version;  // the rope's Bullet nodes reload x and v
    }

    /// Wisps against wisps (sim/volume/wisp_contact.h) after the substep:
    /// vertices of different guides kept a wisp diameter apart, the moves
    /// turned into velocity (position-based dynamics), then each moved
    /// guide's lengths and clearance restored.
    void separateWisps(const guides::SubstepContext& ctx) {
        const VolumeSettings& vs = set.settings.volume;
        beforeWisps = set.x;
        volume::ContactInput in;
        in.x = set.x.data();
        in.x0 = substepStart.data();
        in.mass = set.mass.data();
        in.count = set.x.size();
        in.verticesPerGuide = size_t(set.vertices);
        in.distance = 2.f * vs.contactScale * volume::wispRadius(set.settings.hairsPerGuide, vs.targetDensity);
        in.iterations = vs.contactIterations;
        in.friction = set.settings.friction;
        const auto parallel = [&](size_t count, const std::function<void(size_t, size_t)>& f) {
            skeleton.parallel(count, std::max<size_t>(1, count / 64), f);
        };
        if (wisps->apply(in, parallel) == 0) return;
        const strand::HeadQuery* hq = ctx.collidingHead();
        const float invH = 1.f / ctx.h;
        skeleton.parallel(set.count, 1, [&](size_t b, size_t e) {
            for (size_t g = b; g < e; ++g) {
                const size_t first = set.vertex(g, 0), end = first + size_t(set.vertices);
                bool moved = false;
                for (size_t k = first; k < end && !moved; ++k) moved = set.x[k] != beforeWisps[k];
                if (!moved) continue;
                // The contact's own moves become velocity; restoring lengths
                // then moves vertices without adding any (turning the
                // follow-the-leader moves into velocity too added 13% of the
                // crossing wisps' released energy at the impact).
                for (size_t k = first + 1; k < end; ++k) set.v[k] += (set.x[k] - beforeWisps[k]) * invH;
                relax(g, hq);
            }
        });
        ++set.version;
    }

    // solver::StrandModel: the guides' own step.
    void beginStep(const HeadPose& head, bool cut) override;
    void resetToRest(const HeadPose& head) override;
    void substep(const solver::Substep& sub) override;
    void endStep(bool cut, StepStats& counters) override;
    StepStats measure(const Collider* collider) const override;
    void restoreLengths(size_t g, float, Vec3f* x) const override {
        strand::followTheLeader(x, &set.restLength[set.segment(g, 0)], size_t(set.vertices));
    }
};

GuideSolver::GuideSolver(const GuideSettings& settings) {
    settings.validate();
    impl_ = std::make_unique<Impl>(settings);
    skeleton_ = &impl_->skeleton;
}

GuideSolver::~GuideSolver() = default;

void GuideSolver::initialize(const std::vector<SurfaceFrame>& roots, const HeadPose& head,
                             const std::vector<std::vector<Vec3f>>* groom) {
    Impl& m = *impl_;
    GuideSet& set = m.set;
    const GuideSettings& s = set.settings;
    if (groom && groom->size() != roots.size())
        throw Error(cat("guide solver: ", groom->size(), " groomed strands for ", roots.size(), " roots"));
    set.resize(roots, s.segments + 1);
    set.segments = s.segments;
    const size_t nv = set.count * set.vertices, ns = set.count * set.segments;
    set.restLength.assign(ns, s.length / float(s.segments));
    set.groomDir.assign(ns, Vec3f::UnitY());
    set.springDir.assign(ns, Vec3f::UnitY());
    set.spring.assign(ns, 0.f);
    set.limitSpring.assign(ns, 0.f);
    set.limitPerIteration.assign(ns, 0.f);
    set.minSpan.assign(ns, 0.f);
    set.maxSpan.assign(ns, 0.f);
    set.restBend.assign(ns, 0.f);
    set.cosMostBend.assign(ns, 0.f);
    set.cosLeastBend.assign(ns, 0.f);
    set.mass.assign(nv, 0.f);

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
        // Lumped masses: each vertex carries half of its two segments. The
        // rod's fibre tapers (hair.radius.root → tip), so its segments' masses
        // do too; rope and rigid take a uniform mass per length.
        const float mu = float(s.guideMassPerLength());
        double guideLength = 0, arc = 0;
        for (int j = 0; j < set.segments; ++j) guideLength += set.restLength[set.segment(g, j)];
        for (int j = 0; j < set.segments; ++j) {
            const float l = set.restLength[set.segment(g, j)];
            const float half = s.formulation == GuideFormulation::Rod && s.taperedFibre
                                   ? float(0.5 * guides::rodSegmentMass(s, arc / guideLength, (arc + l) / guideLength, l))
                                   : 0.5f * mu * l;
            arc += l;
            if (j > 0) set.mass[set.vertex(g, j)] += half;
            set.mass[set.vertex(g, j + 1)] += half;
        }
        for (int j = 0; j < set.segments; ++j) {
            const size_t seg = set.segment(g, j);
            // The joint drive acts on its own segment (inertia m·l² about the
            // joint); what hangs beyond is carried along (strand::relaxJoints).
            const float inertia = set.mass[set.vertex(g, j + 1)] * set.restLength[seg] * set.restLength[seg];
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
    set.keepPrevious();

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
    m.grid.reset();
    if (s.volume.enabled && s.formulation != GuideFormulation::Rigid)
        m.grid = std::make_unique<volume::HairGrid>(s.volume);
    m.wisps.reset();
    if (s.volume.enabled && s.volume.contactScale > 0.f && s.formulation != GuideFormulation::Rigid)
        m.wisps = std::make_unique<volume::WispContact>();

    ++set.version;
    if (s.preload) {
        guides::SubstepContext ctx;
        ctx.h = s.timeStep / float(s.substeps);
        ctx.headTransform = head.transform;
        ctx.headCollision = false;
        ctx.head.collider = head.collider.get();  // at the first frame's pose: the rod's pre-load leans on it
        m.forGroups([&](guides::GuideGroup& grp) { grp.preload(ctx); });
    }
    m.skeleton.start(head);
}

void GuideSolver::Impl::beginStep(const HeadPose& head, bool cut) {
    set.headTransform = head.transform;
    strandContacts = 0;
    gridStats = volume::GridStats{};
    if (!cut) formulation->beginStep(head);
}

void GuideSolver::Impl::resetToRest(const HeadPose& head) {
    forGroups([](guides::GuideGroup& grp) { grp.reset(); });
    // The rest shape on the new pose may cross the head or another
    // collider (the new pose is arbitrary): place it outside every one
    // before the cut frame is written, lengths kept (strand::placeSegment).
    if (set.settings.headCollision && head.collider) {
        strand::HeadQuery hq;
        hq.collider = head.collider.get();
        forGroups([&](guides::GuideGroup& grp) {
            for (size_t g = grp.begin(); g < grp.end(); ++g) relax(g, &hq);
        });
    }
    ++set.version;
}

void GuideSolver::Impl::substep(const solver::Substep& sub) {
    guides::SubstepContext ctx;
    static_cast<solver::Substep&>(ctx) = sub;
    ctx.headCollision = set.settings.headCollision;
    if (wisps) substepStart = set.x;  // before the grid's push: a push through another wisp is a crossing too
    if (grid) couple(sub);
    forGroups([&](guides::GuideGroup& grp) { grp.substep(ctx); });
    if (wisps) separateWisps(ctx);
    if (contacts) {
        const strand::HeadQuery* hq = ctx.collidingHead();
        strandContacts += contacts->solve(set, ctx.h, [&](size_t g) { relax(g, hq); });
        ++set.version;
    }
}

void GuideSolver::Impl::endStep(bool cut, StepStats& counters) {
    const GuideSettings& s = set.settings;
    // Velocity guard (GuideSettings::maxSpeed). A NaN speed fails the
    // comparison and is left for measure() to report. Rod and rope only: their groups
    // reload x / v from the set when the version moves, while the rigid
    // formulation's bodies keep their own state (set.v is a read-back).
    size_t clamped = 0;
    if (s.maxSpeed > 0.f && !cut && s.formulation != GuideFormulation::Rigid) {
        for (Vec3f& v : set.v) {
            const float speed = v.norm();
            if (speed > s.maxSpeed) {
                v *= s.maxSpeed / speed;
                ++clamped;
            }
        }
        if (clamped) ++set.version;  // the groups reload the clamped state
    }
    counters.clampedCount = clamped;
    counters.strandContacts = strandContacts;
    counters.maxHairDensity = gridStats.maxDensity;
    counters.volumePushed = gridStats.pushed;
    for (auto& grp : groups) counters.pinnedCount += grp->takePinned();
}

StepStats GuideSolver::Impl::measure(const Collider* collider) const {
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
                // Inside by the head's parts the strand does not ignore (sim/collision/mesh_parts.h).
                if (i > 0 && collider) {
                    const uint32_t ignore = set.ignoredParts(g);
                    const float d = ignore ? collider->signedDistanceIgnoring(set.x[k], nullptr, ignore)
                                           : collider->signedDistance(set.x[k]);
                    if (d < 0.f) {
                        ++p.inside;
                        p.maxDepth = std::max(p.maxDepth, double(-d));
                    }
                }
            }
        }
        p.energy = grp.kineticEnergy();
    };
    skeleton.parallel(groups.size(), 1, [&](size_t b, size_t e) {
        for (size_t gi = b; gi != e; ++gi) body(gi);
    });
    StepStats s;
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

std::vector<char> GuideSolver::saveState() const {
    const Impl& m = *impl_;
    const GuideSet& set = m.set;
    if (set.settings.formulation == GuideFormulation::Rigid)
        throw Error("guide solver: checkpoints need the rod or rope formulation (the rigid one keeps state inside Bullet)");
    BlobWriter w;
    m.skeleton.saveClock(w);
    w.put(set.headTransform.matrix());
    set.save(w);
    for (const auto& grp : m.groups) grp->save(w);
    return std::move(w.data);
}

void GuideSolver::restoreState(const std::vector<char>& state) {
    Impl& m = *impl_;
    GuideSet& set = m.set;
    m.skeleton.requireStarted("restoreState()");
    if (set.settings.formulation == GuideFormulation::Rigid)
        throw Error("guide solver: checkpoints need the rod or rope formulation");
    BlobReader r(state, "guide solver");
    m.skeleton.restoreClock(r);
    set.headTransform.matrix() = r.get<Eigen::Matrix4f>();
    set.restore(r);
    for (auto& grp : m.groups) grp->restore(r);
    r.finish();
    // The Bullet nodes of every world reload x and v before the next step:
    // a rope node's whole state is its position and velocity.
    ++set.version;
}

const GuideSettings& GuideSolver::settings() const { return impl_->set.settings; }
StepStats GuideSolver::measure(const Collider* collider) const { return impl_->measure(collider); }

void GuideSolver::setIgnoredParts(std::vector<uint32_t> masks) {
    if (!masks.empty() && masks.size() != impl_->set.count)
        throw Error(cat("guide solver: ", masks.size(), " part masks for ", impl_->set.count, " guides"));
    impl_->set.ignoreParts = std::move(masks);
}

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
