#include "pipeline/stages/shot_simulation.h"

#include "core/log.h"
#include "pipeline/scene/curly_settings.h"
#include "pipeline/scene/follower_settings.h"
#include "pipeline/groom/groom_import.h"
#include "pipeline/scene/sim_settings.h"
#include "sim/curly/curly_wet.h"
#include "sim/followers/followers.h"
#include "sim/strands/groom.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace hp {

namespace {

double msSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

void evaluateRoots(const TriangleMesh& mesh, const std::vector<SurfacePoint>& roots, std::vector<SurfaceFrame>& out) {
    out.resize(roots.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, roots.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) out[i] = evaluate(mesh, roots[i]);
    });
}

}  // namespace

float frameAlignedStep(double fps, double maxStep) {
    const double frame = 1.0 / fps;
    // The step keys are floats (0.02f is 0.0199999996): compare with a tolerance.
    const double steps = std::max(1.0, std::ceil(frame / maxStep - 1e-5));
    return float(frame / steps);
}

/// The two strand models behind one interface: the rigid chain
/// (sim/guides/guides.h: rod, rope or rigid formulation) and curly-wet
/// (sim/curly/curly_wet.h). Both solvers step, keep time and write frames
/// as a StrandSolver (sim/solver/strand_solver.h); a model adds how it is
/// initialised, what it does around a step, and its checkpoints.
class GuideModel {
  public:
    explicit GuideModel(StrandSolver& solver) : solver(solver) {}
    virtual ~GuideModel() = default;
    virtual void initialize(const std::vector<SurfaceFrame>& roots, const HeadPose& head,
                            const std::vector<std::vector<Vec3f>>* groom) = 0;
    /// One step of the solver (a model may set inputs before it or report after it).
    virtual StepStats step(const std::vector<SurfaceFrame>& roots, const HeadPose& head) {
        return solver.step(roots, head);
    }
    /// The head's parts each guide ignores (GuideSolver::setIgnoredParts); a
    /// model without the notion collides with every part.
    virtual void setIgnoredParts(const std::vector<uint32_t>&) {}
    /// -1 unless the model has a saturation.
    virtual double saturation() const { return -1; }
    /// False when the model's state cannot be saved exactly (then a stopped
    /// simulation restarts from the first frame instead of a checkpoint).
    virtual bool canCheckpoint() const { return true; }
    virtual std::vector<char> saveState() const = 0;
    virtual void restoreState(const std::vector<char>& state) = 0;
    virtual const char* name() const = 0;

    StrandSolver& solver;  ///< the derived model's own solver
};

namespace {

class RigidChainModel final : public GuideModel {
  public:
    explicit RigidChainModel(const GuideSettings& s) : GuideModel(solver_), solver_(s) {}
    void initialize(const std::vector<SurfaceFrame>& roots, const HeadPose& head,
                    const std::vector<std::vector<Vec3f>>* groom) override {
        solver_.initialize(roots, head, groom);
    }
    void setIgnoredParts(const std::vector<uint32_t>& masks) override { solver_.setIgnoredParts(masks); }
    bool canCheckpoint() const override { return solver_.settings().formulation != GuideFormulation::Rigid; }
    std::vector<char> saveState() const override { return solver_.saveState(); }
    void restoreState(const std::vector<char>& state) override { solver_.restoreState(state); }
    const char* name() const override { return formulationName(solver_.settings().formulation); }

  private:
    GuideSolver solver_;
};

class CurlyWetModel final : public GuideModel {
  public:
    CurlyWetModel(const Scene& scene, const CurlyWetSettings& s) : GuideModel(solver_), scene_(scene), solver_(s) {}
    void initialize(const std::vector<SurfaceFrame>& roots, const HeadPose& head,
                    const std::vector<std::vector<Vec3f>>*) override {
        // The curly model grooms its own helices.
        solver_.setSaturation(sceneSaturation(scene_, head.time));
        solver_.initialize(roots, head);
    }
    StepStats step(const std::vector<SurfaceFrame>& roots, const HeadPose& head) override {
        solver_.setSaturation(sceneSaturation(scene_, head.time));
        const StepStats& c = solver_.step(roots, head);
        if (c.implicitFailures > 0)
            logWarning("curly-wet: at t = ", head.time, " s the implicit spring step of ", c.implicitFailures,
                       " strand-substep(s) was not finite; those strands skipped their curl, bending and core "
                       "forces for it (try a smaller simulation.time_step, more substeps or softer hair.curly "
                       "stiffnesses)");
        return c;
    }
    double saturation() const override { return solver_.lastStats().meanSaturation; }
    std::vector<char> saveState() const override { return solver_.saveState(); }
    void restoreState(const std::vector<char>& state) override { solver_.restoreState(state); }
    const char* name() const override { return "curly-wet"; }

  private:
    const Scene& scene_;
    CurlyWetSolver solver_;
};

/// Rest shapes of the guides in their own root frames (x = tangent,
/// y = normal, z = tangent × normal: the followers' frame, sim/followers/followers.h),
/// from the guides as written at t0. (The frame's z once was normal ×
/// tangent, a mirror image: a guide's rest shape with any sideways part then
/// read as a rotation away from rest, and the followers turned by it.)
RestShapes restShapes(const StrandFrame& guides, const std::vector<SurfaceFrame>& roots) {
    RestShapes shapes;
    std::vector<Vec3f> local;
    for (size_t g = 0; g < roots.size(); ++g) {
        const Eigen::Matrix3f toWorld = rootAxes(roots[g]);
        const uint32_t first = guides.first(g), n = guides.vertexCount(g);
        local.resize(n);
        for (uint32_t v = 0; v < n; ++v) local[v] = toWorld.transpose() * (guides.positions[first + v] - roots[g].position);
        shapes.add(local.data(), n);
    }
    return shapes;
}

}  // namespace

std::string SimFrameStats::json() const {
    std::ostringstream o;
    o.precision(9);
    o << "{\"frame\": " << frame << ", \"time\": " << time << ", \"steps\": " << guides.steps
      << ", \"max_length_error\": " << guides.maxLengthError << ", \"mean_length_error\": " << guides.meanLengthError
      << ", \"penetration_count\": " << guides.penetrationCount << ", \"max_penetration\": " << guides.maxPenetration
      << ", \"kinetic_energy\": " << guides.kineticEnergy << ", \"nan_count\": " << guides.nanCount
      << ", \"pinned\": " << guides.pinnedCount
      << ", \"strand_contacts\": " << guides.strandContacts << ", \"reset\": " << (guides.reset ? "true" : "false")
      << ", \"cuts\": " << guides.cuts
      << ", \"ms_per_step\": " << guides.msPerStep << ", \"head_ms\": " << headMs
      << ", \"follower_ms\": " << followerMs << ", \"follower_projected\": " << followerProjected
      << ", \"frame_ms\": " << totalMs << ", \"strands\": " << strands << ", \"vertices\": " << vertices;
    if (saturation >= 0) o << ", \"saturation\": " << saturation;
    if (settleSeconds >= 0)
        o << ", \"settle\": {\"seconds\": " << settleSeconds << ", \"kinetic_energy\": " << settleEnergy
          << ", \"at_rest\": " << (settleConverged ? "true" : "false") << ", \"cached\": "
          << (settleCached ? "true" : "false") << "}";
    o << ", \"guides\": {\"max_length_error\": " << guides.maxLengthError
      << ", \"mean_length_error\": " << guides.meanLengthError << ", \"penetration_count\": " << guides.penetrationCount
      << ", \"max_penetration\": " << guides.maxPenetration << "}";
    o << ", \"followers\": {\"max_length_error\": " << followers.maxLengthError
      << ", \"mean_length_error\": " << followers.meanLengthError
      << ", \"penetration_count\": " << followers.penetrationCount
      << ", \"max_penetration\": " << followers.maxPenetration << ", \"projected\": " << followerProjected
      << ", \"bent\": " << followers.bent << ", \"pinned\": " << followers.pinned << "}";
    o << "}";
    return o.str();
}

ShotSimulation::ShotSimulation(const Scene& scene, double fps, int startFrame, const SettleCache& settleCache,
                               bool rebuildOnly)
    : scene_(scene), fps_(fps), frame_(startFrame), clip_(scene.frames("frames")) {
    if (!sceneHasHead(scene)) scene.fail("head.file", "the shot has hair but no head: set head.file");
    head_ = loadHead(scene);
    std::unique_ptr<ImportedGroom> imported;
    if (sceneHasGroomFile(scene)) {
        if (usesCurlyWetModel(scene))
            scene.fail("hair.groom.file", "an imported groom needs the rigid-chain model (the curly-wet model grooms "
                                          "its own helices)");
        imported = std::make_unique<ImportedGroom>(importGroom(scene, head_, guideSettings(scene).segments + 1));
        roots_ = imported->roots;
    } else {
        roots_ = placeGroomRoots(scene, head_);
    }
    if (roots_.guides.empty()) scene.fail("hair.guides.count", "the groom needs at least one guide");
    GuideSettings settings;
    if (usesCurlyWetModel(scene)) {
        CurlyWetSettings curly = curlyWetSettings(scene);
        curly.timeStep = frameAlignedStep(fps, curly.timeStep);
        model_ = std::make_unique<CurlyWetModel>(scene, curly);
    } else {
        settings = guideSettings(scene);
        settings.timeStep = frameAlignedStep(fps, settings.timeStep);
        model_ = std::make_unique<RigidChainModel>(settings);
    }

    const double t0 = startFrame / fps;
    pose_ = head_.motion->sample(t0);
    evaluateRoots(pose_.mesh, roots_.guides, guideFrames_);
    initializeGuides(settings, imported.get(), settleCache);
    // A head that folds into itself: each strand ignores the parts its root
    // lies inside (docs/colliders.md), pose by pose.
    updateIgnoredParts(pose_.mesh);
    if (std::any_of(ignoredParts_.begin(), ignoredParts_.end(), [](uint32_t m) { return m != 0; }))
        logInfo("head: ", head_.motion->partition().count(), " parts overlap; at the first frame ",
                std::count_if(ignoredParts_.begin(), ignoredParts_.end(), [](uint32_t m) { return m != 0; }),
                " strands grow inside another part and ignore it");

    // Followers learn the guides' rest shapes from the guides at t0.
    StrandFrame rest;
    model_->solver.write(rest, t0);
    FollowerGroom groom;
    groom.guideRoots = guideFrames_;
    groom.guideShapes = restShapes(rest, guideFrames_);
    evaluateRoots(pose_.mesh, roots_.followers, followerFrames_);
    groom.followerRoots = followerFrames_;
    groom.followerVertices = {rest.vertexCount(0)};
    float length = 0.f;
    for (uint32_t v = 1; v < rest.vertexCount(0); ++v) length += (rest.positions[v] - rest.positions[v - 1]).norm();
    groom.followerLengths = {length};
    if (imported) groom.followerShapes = std::move(imported->followerShapes);
    if (groom.followerShapes.count() == 0 && (imported || settleRan_))
        groom.followerShapes = nearestGuideShapes(rest, guideFrames_, followerFrames_);
    applyGroomModifiers(groom, groomModifiers(scene));  // rest shapes of clumped, wavy, frizzy followers
    FollowerSettings followerOptions = followerSettings(scene);
    if (usesCurlyWetModel(scene)) {
        const CurlyWetSettings curly = curlyWetSettings(scene);
        followerOptions.rootRadius = curly.rootRadius;
        followerOptions.tipRadius = curly.tipRadius;
    }
    followers_ = std::make_unique<Followers>(groom, followerOptions);
    if (rebuildOnly)
        logVerbose("strand cache: rebuilding followers from the cached guides: ", model_->solver.guideCount(),
                   " guides, ", followers_->followerCount(), " followers");
    else
        logInfo("simulation: ", model_->solver.guideCount(), " guides (", model_->name(), "), ",
                followers_->followerCount(), " followers, from frame ", startFrame);
    produceFrame(t0);
    stats_.settleSeconds = settleRan_ ? settled_.seconds : -1;
    stats_.settleEnergy = settled_.kineticEnergy;
    stats_.settleConverged = settled_.converged;
    stats_.settleCached = settled_.fromCache;
}

void ShotSimulation::updateIgnoredParts(const TriangleMesh& mesh) {
    const MeshPartition& parts = head_.motion->partition();
    if (parts.count() < 2) {
        ignoredParts_.assign(roots_.guides.size() + roots_.followers.size(), 0u);
        return;
    }
    // One call for guides and followers: partsAroundRoots builds an exact
    // collider of every part of this pose, once.
    std::vector<SurfacePoint> roots = roots_.guides;
    roots.insert(roots.end(), roots_.followers.begin(), roots_.followers.end());
    ignoredParts_ = partsAroundRoots(parts, mesh, roots);
    model_->setIgnoredParts({ignoredParts_.begin(), ignoredParts_.begin() + std::ptrdiff_t(roots_.guides.size())});
}

const uint32_t* ShotSimulation::followerIgnoredParts() const {
    if (head_.motion->partition().count() < 2) return nullptr;
    return ignoredParts_.data() + roots_.guides.size();
}

void ShotSimulation::initializeGuides(const GuideSettings& settings, const ImportedGroom* imported,
                                      const SettleCache& settleCache) {
    if (usesCurlyWetModel(scene_)) {
        model_->initialize(guideFrames_, pose_, nullptr);  // the curly model grooms its own helices
        return;
    }
    std::vector<std::vector<Vec3f>> strands;
    bool shaped = false;
    auto combed = [&](float droop, const Vec3f& direction) {
        GroomSettings groom;
        groom.style = GroomStyle::Combed;
        groom.segments = settings.segments;
        groom.length = settings.length;
        groom.droop = droop;
        groom.direction = direction;
        groom.clearance = 2.f * settings.collisionRadius;
        return groomStrands(guideFrames_, groom, pose_.collider.get());
    };
    if (imported) {
        // The user's groom, as drawn: its shape is the rest shape.
        strands = strandsAt(imported->guideShapes, guideFrames_);
        shaped = true;
    } else if (scene_.text("hair.groom.style") == "combed") {
        strands = combed(float(scene_.number("hair.groom.droop")), scene_.vec3f("hair.groom.direction"));
        shaped = true;
    }
    const double settle = scene_.number("hair.groom.settle");
    if (!imported && settle > 0 && !shaped) {
        // A straight strand on the crown stands exactly against gravity, a
        // balance it never leaves: tilt the straight groom a little toward
        // the back (-Z, the default scalp's side) before it settles.
        strands = combed(0.2f, Vec3f(0.f, 0.f, -1.f));
        shaped = true;
    }
    if (!imported && settle > 0) {
        SettledGroom s = settleGroom(settings, guideFrames_, pose_, shaped ? &strands : nullptr, settle,
                                     float(scene_.number("hair.groom.settle_stiffness")),
                                     scene_.number("hair.groom.settle_speed"), settleCache,
                                     settleSceneKeys(scene_));
        strands = std::move(s.strands);
        shaped = true;
        settled_ = std::move(s);
        settleRan_ = true;
    }
    model_->initialize(guideFrames_, pose_, shaped ? &strands : nullptr);
}

ShotSimulation::~ShotSimulation() = default;

size_t ShotSimulation::guideCount() const { return model_->solver.guideCount(); }
bool ShotSimulation::canCheckpoint() const { return model_->canCheckpoint(); }
size_t ShotSimulation::followerCount() const { return followers_->followerCount(); }

const StrandFrame& ShotSimulation::advanceTo(int frame) {
    if (frame < frame_) throw std::logic_error(cat("simulation cannot go back from frame ", frame_, " to ", frame));
    if (frame == frame_) return strands_;
    // The followers carry state from the frame produced before (velocities
    // by difference, pinned vertices held toward their previous place), so
    // every clip frame on the way is produced: a frame's strands are the
    // same bits whichever frames a run asks for.
    for (int f : clip_)
        if (f > frame_ && f < frame) stepTo(f);
    stepTo(frame);
    return strands_;
}

void ShotSimulation::stepTo(int frame) {
    rebuilt_.reset();
    const double target = frame / fps_;
    // Steps are frame-aligned, so the frame is a step's end; the tolerance
    // absorbs the rounding of a float step accumulated over the shot.
    const double tolerance = 1e-4 / fps_;
    while (model_->solver.time() < target - tolerance) {
        const double t = model_->solver.nextTime();
        const auto headStart = std::chrono::steady_clock::now();
        const HeadPose pose = head_.motion->sample(t);
        evaluateRoots(pose.mesh, roots_.guides, guideFrames_);
        // A head that folds into itself: the parts each guide's root lies
        // inside at the step's end, which the fold changes as it moves.
        if (head_.motion->partition().count() > 1)
            model_->setIgnoredParts(partsAroundRoots(head_.motion->partition(), pose.mesh, roots_.guides));
        pendingHeadMs_ += msSince(headStart);
        const StepStats s = model_->step(guideFrames_, pose);
        if (pendingSteps_++ == 0) pending_ = s;
        else pending_.accumulate(s);
        if (s.nanCount > 0)
            throw FrameError(cat("simulation diverged before frame ", frame, " (t = ", t, " s): ", s.nanCount,
                                 " non-finite guide values",
                                 s.firstNonFinite >= 0 ? cat(", first in guide strand ", s.firstNonFinite) : "",
                                 "; try a smaller simulation.time_step or more substeps"));
    }
    frame_ = frame;
    produceFrame(std::min(target, model_->solver.time()));
}

void ShotSimulation::produceFrame(double time) {
    const auto start = std::chrono::steady_clock::now();
    const auto headStart = std::chrono::steady_clock::now();
    pose_ = head_.motion->sample(time);
    evaluateRoots(pose_.mesh, roots_.guides, guideFrames_);
    evaluateRoots(pose_.mesh, roots_.followers, followerFrames_);
    if (head_.motion->partition().count() > 1) updateIgnoredParts(pose_.mesh);
    const double headMs = pendingHeadMs_ + msSince(headStart);

    // The guides are written into the frame in place; the followers are
    // appended after them (their velocities are differences from the
    // previous frame, which the buffer still holds).
    const double dt = stats_.strands > 0 ? time - stats_.time : 0.0;
    StrandFrame guides;
    model_->solver.write(guides, time);
    const auto followerStart = std::chrono::steady_clock::now();
    FollowerStats fs =
        followers_->update({guides, guideFrames_, followerFrames_, pose_.collider.get(), dt, followerIgnoredParts()},
                           strands_);
    strands_.frame = frame_;
    strands_.time = time;
    // What rebuilds this frame's followers (strand cache version 2): the
    // guides, the step's dt when velocities came by difference, the pins.
    previousSource_ = std::move(source_);
    source_ = FollowerSource{};
    source_->guides = std::move(guides);
    source_->guides.frame = frame_;
    source_->guides.time = time;
    source_->dt = fs.differenceVelocities ? dt : 0.0;
    source_->pins = std::move(fs.pins);

    stats_ = SimFrameStats{};
    stats_.frame = frame_;
    stats_.time = time;
    stats_.guides = pendingSteps_ ? pending_ : StepStats{};
    stats_.guides.steps = pendingSteps_;
    stats_.followerProjected = fs.projected;
    const Followers::LengthError lengthError = followers_->lengthError(strands_);
    stats_.followers = {lengthError.max, lengthError.mean, fs.penetrationCount, fs.maxPenetration, fs.bent, fs.pinned};
    stats_.followerMs = msSince(followerStart);
    stats_.headMs = headMs;
    stats_.strands = strands_.strandCount();
    stats_.vertices = strands_.vertexCount();
    stats_.saturation = model_->saturation();
    stats_.totalMs = msSince(start) + pending_.msPerStep * double(pendingSteps_);
    pending_ = StepStats{};
    pendingSteps_ = 0;
    pendingHeadMs_ = 0;
}

// ---- followers rebuilt from cached guides ----------------------------------

std::optional<CachedGuides> ShotSimulation::cachedGuides() const {
    if (!source_) return std::nullopt;
    CachedGuides g;
    g.strands = strands_.strandCount();
    g.vertices = strands_.vertexCount();
    g.current = *source_;
    if (source_->dt > 0.0) {
        if (!previousSource_) return std::nullopt;  // resumed from a version 1 cache: no record of the frame before
        g.previous = *previousSource_;
    }
    return g;
}

void ShotSimulation::rebuildOne(const FollowerSource& source, bool previousInBuffer, const std::string& file) {
    pose_ = head_.motion->sample(source.guides.time);
    evaluateRoots(pose_.mesh, roots_.guides, guideFrames_);
    evaluateRoots(pose_.mesh, roots_.followers, followerFrames_);
    if (head_.motion->partition().count() > 1) updateIgnoredParts(pose_.mesh);
    if (source.dt > 0.0 && !previousInBuffer) followers_->adoptPins(strands_, source.pins);
    const FollowerStats fs = followers_->update(
        {source.guides, guideFrames_, followerFrames_, pose_.collider.get(), source.dt, followerIgnoredParts()},
        strands_);
    strands_.frame = source.guides.frame;
    strands_.time = source.guides.time;
    // The simulation's pins come back only when every input is the same: a
    // scene edited since (hair keys, head) or another build would rebuild
    // other hair silently.
    bool same = fs.pins.size() == source.pins.size();
    for (size_t i = 0; same && i < fs.pins.size(); ++i)
        same = fs.pins[i].vertex == source.pins[i].vertex &&
               std::memcmp(fs.pins[i].last.data(), source.pins[i].last.data(), sizeof(Vec3f)) == 0;
    if (!same || (source.dt > 0.0) != fs.differenceVelocities)
        throw AssetError(file, cat("the followers of frame ", source.guides.frame,
                                   " rebuild differently from the simulation that cached them (the scene's hair or "
                                   "head changed since, or another build): re-simulate with --force"));
    rebuilt_ = {source.guides.frame, source.guides.time};
}

const StrandFrame& ShotSimulation::rebuild(const CachedGuides& cached, const std::string& file) {
    if (cached.strands != guideCount() + followerCount() || cached.current.guides.guideCount != guideCount())
        throw AssetError(file, cat("holds ", cached.current.guides.guideCount, " guides of ", cached.strands,
                                   " strands; the scene grows ", guideCount(), " guides and ", followerCount(),
                                   " followers (re-simulate with --force)"));
    const FollowerSource& now = cached.current;
    const bool chained = now.dt > 0.0;
    if (chained && !cached.previous)
        throw AssetError(file, "strand cache lacks the frame before, which its follower velocities need");
    // Frames read in order rebuild once each: the buffer already holds the one before.
    const bool inBuffer = chained && rebuilt_ && rebuilt_->first == cached.previous->guides.frame &&
                          rebuilt_->second == cached.previous->guides.time;
    rebuilt_.reset();
    if (chained && !inBuffer) rebuildOne(*cached.previous, false, file);
    rebuildOne(now, chained, file);
    return strands_;
}

// ---- checkpoints -------------------------------------------------------------
//
// char[8] "HPCHECKP", u32 version, i32 frame, u32 model name length, model
// name, u64 state size, state bytes (the solver's own serialisation).

namespace {
constexpr char kCheckpointMagic[8] = {'H', 'P', 'C', 'H', 'E', 'C', 'K', 'P'};
constexpr uint32_t kCheckpointVersion = 1;
}  // namespace

void ShotSimulation::saveCheckpoint(const fs::path& file) const {
    const std::vector<char> state = model_->saveState();
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(file.string(), std::strerror(errno));
    const std::string model = model_->name();
    const uint32_t nameLength = uint32_t(model.size());
    const uint64_t size = state.size();
    const int32_t frame = frame_;
    out.write(kCheckpointMagic, sizeof kCheckpointMagic);
    out.write(reinterpret_cast<const char*>(&kCheckpointVersion), sizeof kCheckpointVersion);
    out.write(reinterpret_cast<const char*>(&frame), sizeof frame);
    out.write(reinterpret_cast<const char*>(&nameLength), sizeof nameLength);
    out.write(model.data(), std::streamsize(model.size()));
    out.write(reinterpret_cast<const char*>(&size), sizeof size);
    out.write(state.data(), std::streamsize(state.size()));
    out.close();
    if (!out) throw IoError(file.string(), "write failed (disk full?)");
}

void ShotSimulation::restoreCheckpoint(const fs::path& file, const StrandFrame& strands,
                                       const std::optional<FollowerSource>& source) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw AssetError(file.string(), "cannot open checkpoint");
    char magic[8];
    uint32_t version = 0, nameLength = 0;
    int32_t frame = 0;
    uint64_t size = 0;
    in.read(magic, sizeof magic);
    in.read(reinterpret_cast<char*>(&version), sizeof version);
    in.read(reinterpret_cast<char*>(&frame), sizeof frame);
    in.read(reinterpret_cast<char*>(&nameLength), sizeof nameLength);
    if (!in || std::memcmp(magic, kCheckpointMagic, sizeof magic) != 0 || version != kCheckpointVersion ||
        nameLength > 64)
        throw AssetError(file.string(), "not a hairpipe checkpoint of this version");
    std::string model(nameLength, '\0');
    in.read(model.data(), nameLength);
    in.read(reinterpret_cast<char*>(&size), sizeof size);
    if (!in || model != model_->name()) throw AssetError(file.string(), "checkpoint of another strand model: " + model);
    std::error_code ec;
    if (size > fs::file_size(file, ec)) throw AssetError(file.string(), "truncated checkpoint");
    std::vector<char> state(size);
    in.read(state.data(), std::streamsize(size));
    if (!in) throw AssetError(file.string(), "truncated checkpoint");
    if (strands.frame != frame || strands.strandCount() != guideCount() + followerCount())
        throw AssetError(file.string(), cat("checkpoint of frame ", frame, " does not match the cached strands of frame ",
                                            strands.frame));
    model_->restoreState(state);
    frame_ = frame;
    strands_ = strands;
    previousSource_.reset();
    source_ = source;
    // The restored buffer is what the followers wrote last (velocities by difference).
    followers_->adoptPrevious(strands_);
    pose_ = head_.motion->sample(frame / fps_);
    stats_ = SimFrameStats{};
    stats_.frame = frame;
    stats_.time = strands.time;
    stats_.strands = strands_.strandCount();
    stats_.vertices = strands_.vertexCount();
    pending_ = StepStats{};
    pendingSteps_ = 0;
    pendingHeadMs_ = 0;
}

}  // namespace hp
