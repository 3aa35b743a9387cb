// Internal to hp_sim (not installed, not included outside sim/): the guides'
// shared state and the Bullet worlds that advance them.
//
// The solver (sim/guides/guides.cpp) partitions the guides into groups of
// `strandsPerWorld` consecutive guides, each group owning one Bullet world. A
// group reads and writes only its own guides' slice of GuideSet's arrays, so
// groups run in parallel and the result does not depend on the thread count.
// A Formulation holds what its groups share (shapes, the head mesh) and is
// updated serially between steps. Bullet appears only in the .cpp files.
#pragma once

#include "sim/guides/guides.h"
#include "sim/guides/joint_kernels.h"
#include "sim/solver/damping.h"
#include "sim/solver/length_kernels.h"
#include "sim/solver/skeleton.h"
#include "sim/solver/strand_state.h"

#include <cmath>
#include <functional>
#include <memory>
#include <vector>

namespace hp::guides {

using strand::Mat3f;
using strand::Quatf;

/// Rest shape, pre-load and state of every guide, structure of arrays (the
/// state and root targets: solver::StrandState). Per-segment arrays hold
/// `segments` entries per guide, per-vertex arrays `vertices` = `segments + 1`;
/// guide g's vertex i is at g * vertices + i.
struct GuideSet : solver::StrandState {
    GuideSettings settings;
    int segments = 0;

    // Rest shape in root-local coordinates (see strand::rootRotation).
    std::vector<float> restLength;    ///< per segment
    std::vector<Vec3f> groomDir;      ///< per segment: unit rest direction e_j
    std::vector<float> restBend;      ///< per segment: rest angle to the previous segment (0 for the first)
    std::vector<float> cosMostBend, cosLeastBend;  ///< per segment: projection limit bounds (strand::bendBounds)
    std::vector<Vec3f> springDir;     ///< per segment: rope spring target t_j (e_j turned by the pre-load)
    std::vector<float> spring;        ///< per segment: rope joint spring fraction per Bullet step
    std::vector<float> limitSpring;   ///< per segment: rope limit spring fraction per Bullet step
    std::vector<float> limitPerIteration;  ///< per segment: the same spread over Bullet's link iterations
    std::vector<float> minSpan, maxSpan;   ///< per segment: rope bend limits as spans (strand::bendLimitSpan)
    std::vector<float> mass;          ///< per vertex (0 for the kinematic root)
    /// Per guide: the head's parts it ignores (strand::HeadQuery::ignoreParts);
    /// empty: none (GuideSolver::setIgnoredParts).
    std::vector<uint32_t> ignoreParts;
    uint32_t ignoredParts(size_t g) const { return ignoreParts.empty() ? 0u : ignoreParts[g]; }

    /// Bumped whenever x / v are written outside a group's own substep (a
    /// reset, strand-strand contacts), so the groups reload their worlds.
    unsigned version = 0;

    /// The head's rigid pose at the end of the current step.
    Eigen::Isometry3f headTransform = Eigen::Isometry3f::Identity();

    size_t vertex(size_t guide, int i) const { return guide * vertices + i; }
    size_t segment(size_t guide, int j) const { return guide * segments + j; }
    /// Joint parameters of guide g for strand::relaxJoints.
    strand::JointParams joints(size_t g) {
        strand::JointParams p;
        const size_t s0 = segment(g, 0);
        p.restLength = &restLength[s0];
        p.restDir = &groomDir[s0];
        p.restBend = &restBend[s0];
        p.cosMostBend = &cosMostBend[s0];
        p.cosLeastBend = &cosLeastBend[s0];
        p.springDir = &springDir[s0];
        p.spring = &spring[s0];
        p.limitSpring = &limitSpring[s0];
        p.limit = settings.bendLimit * float(M_PI / 180.0);
        p.projection = settings.projectionAngle * float(M_PI / 180.0);
        return p;
    }
    /// Writes guide g's rest shape rooted at (p, R) into out[0..vertices).
    void restShape(size_t g, const Vec3f& p, const Mat3f& R, Vec3f* out) const;
    /// Puts guides [begin, end) in their rest shape at the end-of-step roots, at rest.
    void resetGuides(size_t begin, size_t end);
    /// Kinetic energy of guides [begin, end), J.
    double kineticEnergy(size_t begin, size_t end) const;
    /// Largest bend of guides [begin, end) relative to the rest shape (maxBendAngle), radians.
    float maxBend(size_t begin, size_t end) const;
};

/// What one Bullet step needs: the skeleton's substep (h, alpha, the head
/// collider and the head's rigid pose at this Bullet step's end) and whether
/// the guides collide with the head.
struct SubstepContext : solver::Substep {
    bool headCollision = true; ///< false: skip projection (head.collider may still be set)

    /// The head the kernels project out of: null when collision is off or there is no collider.
    const strand::HeadQuery* collidingHead() const { return headCollision && head.collider ? &head : nullptr; }
};

/// One Bullet world advancing guides [begin, end) of a GuideSet.
class GuideGroup {
  public:
    GuideGroup(GuideSet& set, size_t begin, size_t end) : set_(set), begin_(begin), end_(end) {}
    virtual ~GuideGroup() = default;

    /// Puts the group's guides at rest at the roots' end-of-step pose, at rest
    /// (zero velocity), in the world too. By default in the shared arrays
    /// only (a group that reloads its world from them when set.version moves).
    virtual void reset() { set_.resetGuides(begin_, end_); }
    /// With the guides at rest and the head still, fixes the spring pre-load
    /// so the rest shape is an equilibrium under gravity.
    virtual void preload(const SubstepContext& ctx) = 0;
    /// One Bullet step: reads and writes set.x / set.v of its guides.
    virtual void substep(const SubstepContext& ctx) = 0;
    /// Kinetic energy of its guides, J (by default from the shared arrays).
    virtual double kineticEnergy() const { return set_.kineticEnergy(begin_, end_); }
    /// Largest bend (and twist) angle relative to the rest shape, radians (by
    /// default the bend of the shared arrays, no twist).
    virtual void jointAngles(float& bend, float& twist) const {
        bend = set_.maxBend(begin_, end_);
        twist = 0.f;
    }
    /// Vertices pinned in the last substeps (no place outside the head at
    /// their length), then cleared. Only the rod formulation pins.
    virtual size_t takePinned() { return 0; }
    /// The group's positions in set.x were moved outside its step (the
    /// hair grid's volume push) from `before` (indexed like set.x). A group
    /// that keeps a position history moves it alike, so that its next step
    /// does not read the move as motion; nothing by default.
    virtual void displaced(const Vec3f* /*before*/) {}
    /// State a group keeps beside set.x / set.v (the rod's BDF2 history),
    /// appended to and read back from a checkpoint; none by default.
    virtual void save(BlobWriter&) const {}
    virtual void restore(BlobReader&) {}

    size_t begin() const { return begin_; }
    size_t end() const { return end_; }

  protected:
    GuideSet& set_;
    size_t begin_, end_;
};

/// The serial, shared part of a formulation.
class Formulation {
  public:
    virtual ~Formulation() = default;
    virtual std::unique_ptr<GuideGroup> makeGroup(GuideSet& set, size_t begin, size_t end) = 0;
    /// Called once per solver step before the groups run (serially).
    virtual void beginStep(const HeadPose&) {}
};

std::unique_ptr<Formulation> makeRopeFormulation(const GuideSet& set);
std::unique_ptr<Formulation> makeRodFormulation();
/// The rod formulation's mean mass per length over the taper, kg/m
/// (rod::Material::meanMassPerLength).
double rodMassPerLength(const GuideSettings& s);
/// The rod's mass of the fibre between arc-length fractions t0 and t1, of
/// the given length, kg (rod::Material::segmentMass: the taper).
double rodSegmentMass(const GuideSettings& s, double t0, double t1, double length);
std::unique_ptr<Formulation> makeRigidFormulation(const GuideSet& set, const HeadPose& head);

/// Strand-strand contacts for the rope formulation: Bullet's broadphase and
/// capsule narrowphase over every segment, resolved at position level.
class StrandContacts {
  public:
    explicit StrandContacts(const GuideSet& set);
    ~StrandContacts();
    /// Detects contacts between segments of different guides (and
    /// non-adjacent segments of one guide) in set.x and pushes them apart,
    /// updating set.v by the same displacement / h; then `relax(g)` restores
    /// each touched guide's lengths and head clearance. Returns the number of
    /// contacts. Serial and in a fixed order, so deterministic.
    size_t solve(GuideSet& set, float h, const std::function<void(size_t)>& relax);

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// Lowers Bullet's global contact breaking threshold to hair scale (2 mm);
/// called before any world that has contacts is built.
void useHairScaleContactThreshold();

/// Bend angle of every joint of guide g relative to its rest shape (rope
/// measure: transported frames, no twist); returns the largest, radians.
float maxBendAngle(const GuideSet& set, size_t g, const Vec3f* x, const Quatf& rootRot);

}  // namespace hp::guides
