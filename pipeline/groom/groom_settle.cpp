#include "pipeline/groom/groom_settle.h"

#include "core/bytes.h"
#include "core/errors.h"
#include "core/files.h"
#include "core/log.h"
#include "pipeline/batch/checksum.h"
#include "pipeline/batch/output.h"

#include <algorithm>
#include <cstring>
#include <sstream>

namespace fs = std::filesystem;

namespace hp {

namespace {

constexpr char kMagic[8] = {'H', 'P', 'S', 'E', 'T', 'T', 'L', 'E'};
constexpr uint32_t kVersion = 1;

/// FNV-1a 64 over bytes fed in order.
struct Fnv {
    uint64_t h = 1469598103934665603ull;
    void bytes(const void* data, size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    }
    template <typename T>
    void put(const T& v) { bytes(&v, sizeof v); }
    void points(const std::vector<Vec3f>& v) {
        for (const Vec3f& p : v) bytes(p.data(), sizeof(float) * 3);
    }
};

}  // namespace

std::string settleSceneKeys(const Scene& scene) {
    std::istringstream in(scene.dump());
    std::string out;
    for (std::string line; std::getline(in, line);) {
        // Everything the settled shape depends on: the solver, the guides, the
        // groom, and the rod's material and radius (mass and stiffness).
        const bool relevant = line.rfind("simulation.", 0) == 0 || line.rfind("hair.guides.", 0) == 0 ||
                              line.rfind("hair.groom.", 0) == 0 || line.rfind("hair.material.", 0) == 0 ||
                              line.rfind("hair.radius.", 0) == 0;
        if (!relevant) continue;
        const size_t comment = line.find("    # default");
        out += line.substr(0, comment) + "\n";
    }
    return out;
}

uint64_t settleKey(const GuideSettings& settings, const std::vector<SurfaceFrame>& roots, const HeadPose& pose,
                   const std::vector<std::vector<Vec3f>>* groom, double seconds, const std::string& sceneKeys) {
    Fnv f;
    f.put(kVersion);
    f.bytes(sceneKeys.data(), sceneKeys.size());
    f.put(settings.timeStep);  // frame-aligned from the fps, not a key itself
    f.put(seconds);
    f.put(settings.bendStiffness);
    f.put(settings.limitStiffness);
    for (const SurfaceFrame& r : roots) {
        f.bytes(r.position.data(), 12);
        f.bytes(r.normal.data(), 12);
        f.bytes(r.tangent.data(), 12);
    }
    f.put(uint64_t(groom ? groom->size() : 0));
    if (groom)
        for (const auto& s : *groom) f.points(s);
    f.points(pose.mesh.positions);
    for (const Tri& t : pose.mesh.triangles) f.bytes(t.data(), sizeof(uint32_t) * 3);
    f.put(pose.collider != nullptr);
    return f.h;
}

void writeSettledGroom(const fs::path& file, uint64_t key, const SettledGroom& g) {
    const uint32_t strands = uint32_t(g.strands.size()), vertices = strands ? uint32_t(g.strands[0].size()) : 0;
    ByteWriter w;
    w.bytes(kMagic, 8);
    w.put(kVersion);
    w.put(key);
    w.put(g.seconds);
    w.put(g.kineticEnergy);
    w.put(uint32_t(g.converged));
    w.put(strands);
    w.put(vertices);
    for (const auto& s : g.strands) {
        if (s.size() != vertices) throw Error("settled groom: strands of different lengths");
        w.values(s);
    }
    w.put(crc32Of(w.data.data(), w.data.size()));
    writeAtomically(file, [&](const fs::path& tmp) { writeFileChecked(tmp, w.data.data(), w.data.size()); });
}

bool readSettledGroom(const fs::path& file, uint64_t key, SettledGroom& g) {
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) return false;
    std::vector<char> b;
    try {
        b = readFileBytes(file, "settled groom");
    } catch (const AssetError&) {
        return false;
    }
    // A cache that does not match (other keys, another version, damaged) is
    // simply not reused: the groom is settled again and the file rewritten.
    struct Stale {};
    ByteReader r(b, [](const std::string&) { throw Stale{}; });
    try {
        char magic[8];
        r.bytes(magic, 8);
        if (std::memcmp(magic, kMagic, 8) != 0 || r.get<uint32_t>() != kVersion || r.get<uint64_t>() != key)
            return false;
        uint32_t stored;
        std::memcpy(&stored, b.data() + b.size() - 4, 4);
        if (stored != crc32Of(b.data(), b.size() - 4)) return false;
        g.seconds = r.get<double>();
        g.kineticEnergy = r.get<double>();
        g.converged = r.get<uint32_t>() != 0;
        const uint32_t strands = r.get<uint32_t>(), vertices = r.get<uint32_t>();
        if (r.remaining() < 4 || uint64_t(strands) * vertices * 12 != r.remaining() - 4) return false;
        g.strands.assign(strands, {});
        for (auto& s : g.strands) r.values(s, vertices);
    } catch (const Stale&) {
        return false;
    }
    g.fromCache = true;
    return true;
}

double settleEnergy(const GuideSettings& settings, size_t guides, double restSpeed) {
    const double mass = double(guides) * settings.guideMassPerLength() * double(settings.length);
    return 0.5 * mass * restSpeed * restSpeed;
}

SettledGroom settleGroom(const GuideSettings& settings, const std::vector<SurfaceFrame>& roots, const HeadPose& pose,
                         const std::vector<std::vector<Vec3f>>* groom, double seconds, float stiffness,
                         double restSpeed, const SettleCache& cache, const std::string& sceneKeys) {
    const uint64_t key = settleKey(settings, roots, pose, groom, seconds, sceneKeys);
    SettledGroom g;
    if (!cache.file.empty() && cache.reuse && readSettledGroom(cache.file, key, g) && g.strands.size() == roots.size()) {
        logInfo("groom: settled groom read from ", cache.file.string(), " (", g.seconds, " s, kinetic energy ",
                g.kineticEnergy, " J)");
        return g;
    }
    g = SettledGroom{};
    GuideSettings s = settings;
    s.preload = false;  // the drawn shape is not an equilibrium under gravity: let it find one
    s.damping = std::max(s.damping, kSettleDamping);
    s.bendStiffness *= stiffness;
    s.limitStiffness *= stiffness;
    GuideSolver solver(s);
    solver.initialize(roots, pose, groom);
    HeadPose still = pose;  // the first frame's pose, held still
    const double start = solver.time();
    const double atRest = settleEnergy(settings, roots.size(), restSpeed);
    // Converged only after a few steps: the first step starts from rest.
    constexpr int kMinSteps = 10;
    int steps = 0;
    while (solver.nextTime() - start <= seconds + 1e-9) {
        still.time = solver.nextTime();
        const StepStats& st = solver.step(roots, still);
        ++steps;
        if (st.nanCount > 0)
            throw FrameError(cat("settling the groom diverged after ", solver.time() - start, " s (", st.nanCount,
                                 " non-finite values); try a smaller simulation.time_step or hair.groom.settle: 0"));
        g.kineticEnergy = st.kineticEnergy;
        if (steps >= kMinSteps && st.kineticEnergy < atRest) {
            g.converged = true;
            break;
        }
    }
    g.seconds = solver.time() - start;
    StrandFrame frame;
    solver.write(frame);
    g.strands.resize(frame.strandCount());
    for (size_t i = 0; i < g.strands.size(); ++i)
        g.strands[i].assign(frame.positions.begin() + frame.first(i), frame.positions.begin() + frame.first(i) + frame.vertexCount(i));
    logInfo("groom: settled for ", g.seconds, " s: ",
            g.converged ? cat("at rest (kinetic energy ", g.kineticEnergy, " J < ", atRest, " J)")
                        : cat("time ran out (hair.groom.settle), kinetic energy still ", g.kineticEnergy, " J"));
    if (!cache.file.empty()) {
        fs::create_directories(cache.file.parent_path());
        writeSettledGroom(cache.file, key, g);
    }
    return g;
}

}  // namespace hp
