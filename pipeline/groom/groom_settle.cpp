#include "pipeline/groom/groom_settle.h"

#include "core/errors.h"
#include "core/files.h"
#include "core/log.h"
#include "pipeline/batch/output.h"

#include <zlib.h>

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

uint32_t crc(const std::vector<char>& b, size_t n) {
    return uint32_t(crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(b.data()), uInt(n)));
}

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
    std::vector<char> b;
    auto put = [&](const void* p, size_t n) { b.insert(b.end(), static_cast<const char*>(p), static_cast<const char*>(p) + n); };
    const uint32_t converged = g.converged, strands = uint32_t(g.strands.size()),
                   vertices = strands ? uint32_t(g.strands[0].size()) : 0;
    put(kMagic, 8);
    put(&kVersion, 4);
    put(&key, 8);
    put(&g.seconds, 8);
    put(&g.kineticEnergy, 8);
    put(&converged, 4);
    put(&strands, 4);
    put(&vertices, 4);
    for (const auto& s : g.strands) {
        if (s.size() != vertices) throw Error("settled groom: strands of different lengths");
        put(s.data(), s.size() * 12);
    }
    const uint32_t c = crc(b, b.size());
    put(&c, 4);
    writeAtomically(file, [&](const fs::path& tmp) { writeFileChecked(tmp, b.data(), b.size()); });
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
    constexpr size_t kHeader = 8 + 4 + 8 + 8 + 8 + 4 + 4 + 4;
    if (b.size() < kHeader + 4 || std::memcmp(b.data(), kMagic, 8) != 0) return false;
    uint32_t version, converged, strands, vertices, stored;
    uint64_t fileKey;
    std::memcpy(&version, b.data() + 8, 4);
    std::memcpy(&fileKey, b.data() + 12, 8);
    std::memcpy(&stored, b.data() + b.size() - 4, 4);
    if (version != kVersion || fileKey != key || stored != crc(b, b.size() - 4)) return false;
    std::memcpy(&g.seconds, b.data() + 20, 8);
    std::memcpy(&g.kineticEnergy, b.data() + 28, 8);
    std::memcpy(&converged, b.data() + 36, 4);
    std::memcpy(&strands, b.data() + 40, 4);
    std::memcpy(&vertices, b.data() + 44, 4);
    if (uint64_t(strands) * vertices * 12 != b.size() - kHeader - 4) return false;
    g.converged = converged != 0;
    g.strands.assign(strands, std::vector<Vec3f>(vertices));
    for (uint32_t s = 0; s < strands; ++s)
        std::memcpy(static_cast<void*>(g.strands[s].data()), b.data() + kHeader + size_t(s) * vertices * 12, size_t(vertices) * 12);
    g.fromCache = true;
    return true;
}

SettledGroom settleGroom(const GuideSettings& settings, const std::vector<SurfaceFrame>& roots, const HeadPose& pose,
                         const std::vector<std::vector<Vec3f>>* groom, double seconds, float stiffness,
                         const SettleCache& cache, const std::string& sceneKeys) {
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
        if (steps >= kMinSteps && st.kineticEnergy < kSettledEnergy) {
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
            g.converged ? cat("at rest (kinetic energy ", g.kineticEnergy, " J < ", kSettledEnergy, " J)")
                        : cat("time ran out (hair.groom.settle), kinetic energy still ", g.kineticEnergy, " J"));
    if (!cache.file.empty()) {
        fs::create_directories(cache.file.parent_path());
        writeSettledGroom(cache.file, key, g);
    }
    return g;
}

}  // namespace hp
