#include "pipeline/batch/strand_cache.h"

#include "core/errors.h"
#include "core/bytes.h"
#include "core/files.h"
#include "pipeline/batch/checksum.h"

#include <cstring>
#include <fstream>

namespace hp {

namespace {

constexpr char kMagic[8] = {'H', 'P', 'S', 'T', 'R', 'A', 'N', 'D'};
constexpr uint32_t kHasVelocities = 1u;

static_assert(sizeof(Vec3f) == 3 * sizeof(float), "Vec3f must be packed");

/// Reads a strand cache, naming the file in every refusal.
ByteReader cacheReader(const std::vector<char>& data, const std::string& file) {
    return ByteReader(data, [file](const std::string& why) { throw AssetError(file, "strand cache " + why); });
}

void writeHeader(ByteWriter& w, uint32_t version, bool velocities, const StrandFrame& head, uint64_t strands,
                 uint64_t vertices) {
    w.bytes(kMagic, sizeof kMagic);
    w.put(version);
    w.put(uint32_t(velocities ? kHasVelocities : 0u));
    w.put(int32_t(head.frame));
    w.put(uint32_t(head.guideCount));
    w.put(double(head.time));
    w.put(strands);
    w.put(vertices);
}

void finish(const std::filesystem::path& path, ByteWriter& w) {
    w.put(crc32Of(w.data.data(), w.data.size()));
    writeFileChecked(path, w.data.data(), w.data.size());
}

void writeRecord(ByteWriter& w, const FollowerSource& s, bool velocities) {
    const StrandFrame& g = s.guides;
    w.put(int32_t(g.frame));
    w.put(double(g.time));
    w.put(double(s.dt));
    w.put(uint64_t(g.vertexCount()));
    w.values(g.offsets);
    w.values(g.ids);
    w.values(g.positions);
    w.values(g.radii);
    if (velocities) w.values(g.velocities);
    w.put(uint32_t(s.pins.size()));
    for (const FollowerPin& p : s.pins) {
        w.put(p.vertex);
        w.put(p.last);
    }
}

FollowerSource readRecord(ByteReader& r, uint32_t guides, bool velocities, uint64_t followerVertices) {
    FollowerSource s;
    StrandFrame& g = s.guides;
    g.frame = r.get<int32_t>();
    g.time = r.get<double>();
    s.dt = r.get<double>();
    g.guideCount = guides;
    const uint64_t vertices = r.get<uint64_t>();
    if (vertices > (1ull << 32)) r.fail(cat("guide vertex count ", vertices, " is implausible"));
    r.values(g.offsets, uint64_t(guides) + 1);
    r.values(g.ids, guides);
    r.values(g.positions, vertices);
    r.values(g.radii, vertices);
    if (velocities) r.values(g.velocities, vertices);
    const uint32_t pins = r.get<uint32_t>();
    if (pins > r.remaining() / 16) r.fail("truncated (pins extend past the end of the data)");
    s.pins.resize(pins);
    for (FollowerPin& p : s.pins) {
        p.vertex = r.get<uint32_t>();
        p.last = r.get<Vec3f>();
        if (p.vertex >= followerVertices || !p.last.allFinite())
            r.fail(cat("is inconsistent: pinned vertex ", p.vertex, " of ", followerVertices, " follower vertices"));
    }
    if (!(s.dt >= 0.0 && s.dt < 1e6)) r.fail(cat("is inconsistent: dt ", s.dt));
    try {
        g.validate();
    } catch (const Error& e) {
        r.fail(std::string("is inconsistent: ") + e.what());
    }
    return s;
}

}  // namespace

void writeStrandCache(const std::filesystem::path& path, const StrandFrame& frame) {
    frame.validate();
    ByteWriter w;
    const bool velocities = !frame.velocities.empty();
    writeHeader(w, kStrandCacheVersion, velocities, frame, frame.strandCount(), frame.vertexCount());
    w.values(frame.offsets);
    w.values(frame.ids);
    w.values(frame.positions);
    w.values(frame.radii);
    if (velocities) w.values(frame.velocities);
    finish(path, w);
}

void writeGuideCache(const std::filesystem::path& path, const CachedGuides& guides) {
    const StrandFrame& g = guides.current.guides;
    g.validate();
    if (g.strandCount() != g.guideCount) throw Error("writeGuideCache: the guide frame holds followers");
    const bool velocities = !g.velocities.empty();
    if (guides.previous && (guides.previous->guides.velocities.empty() == velocities ||
                            guides.previous->guides.guideCount != g.guideCount))
        throw Error("writeGuideCache: the previous frame's guides do not match this frame's");
    ByteWriter w;
    writeHeader(w, kGuideCacheVersion, velocities, g, guides.strands, guides.vertices);
    writeRecord(w, guides.current, velocities);
    w.put(uint8_t(guides.previous ? 1 : 0));
    if (guides.previous) writeRecord(w, *guides.previous, velocities);
    finish(path, w);
}

StrandFrame readStrandCache(const std::filesystem::path& path) {
    StrandCacheFile f = readStrandCacheFile(path);
    if (f.version != kStrandCacheVersion)
        throw AssetError(path.string(), "strand cache holds the guides only (version 2, cache.followers: rebuild): "
                                        "read it through pipeline/stages/cached_strands.h, which rebuilds the followers");
    return std::move(f.strands);
}

StrandCacheFile readStrandCacheFile(const std::filesystem::path& path) {
    return parseStrandCacheFile(readFileBytes(path, "strand cache"), path.string());
}

StrandCacheFile parseStrandCacheFile(const std::vector<char>& data, const std::string& name) {
    ByteReader r = cacheReader(data, name);
    char magic[8];
    r.bytes(magic, sizeof magic);
    if (std::memcmp(magic, kMagic, sizeof magic) != 0) r.fail("has a wrong magic number (not a hairpipe strand cache)");
    const uint32_t version = r.get<uint32_t>();
    if (version != kStrandCacheVersion && version != kGuideCacheVersion)
        r.fail(cat("version ", version, " is not supported (this build reads versions ", kStrandCacheVersion, " and ",
                   kGuideCacheVersion, ")"));
    if (data.size() < sizeof(uint32_t)) r.fail("truncated");
    uint32_t stored;
    std::memcpy(&stored, data.data() + data.size() - sizeof stored, sizeof stored);
    if (crc32Of(data.data(), data.size() - sizeof stored) != stored)
        r.fail("checksum mismatch: the file is corrupt or was truncated");

    StrandCacheFile out;
    out.version = version;
    StrandFrame& f = out.strands;
    const uint32_t flags = r.get<uint32_t>();
    f.frame = r.get<int32_t>();
    f.guideCount = r.get<uint32_t>();
    f.time = r.get<double>();
    const uint64_t strands = r.get<uint64_t>();
    const uint64_t vertices = r.get<uint64_t>();
    const bool velocities = flags & kHasVelocities;
    if (strands > (1ull << 32) || vertices > (1ull << 32) || f.guideCount > strands)
        r.fail(cat("sizes are implausible (", strands, " strands, ", vertices, " vertices)"));
    if (version == kGuideCacheVersion) {
        CachedGuides g;
        g.strands = strands;
        g.vertices = vertices;
        g.current = readRecord(r, f.guideCount, velocities, vertices);
        const uint8_t previous = r.get<uint8_t>();
        if (previous > 1) r.fail("is inconsistent: bad previous-frame flag");
        if (previous) g.previous = readRecord(r, f.guideCount, velocities, vertices);
        if (r.remaining() != sizeof(uint32_t)) r.fail("sizes disagree with the file length");
        if (g.current.guides.frame != f.frame || g.current.guides.vertexCount() > vertices)
            r.fail("is inconsistent: the guide record does not match the header");
        out.guides = std::move(g);
        out.strands = StrandFrame{};
        return out;
    }
    // Sizes must match the file length exactly before anything is allocated.
    const uint64_t expected = (strands + 1) * 4 + strands * 4 + vertices * (12 + 4) + (velocities ? vertices * 12 : 0) +
                              sizeof(uint32_t);
    if (expected != r.remaining())
        r.fail(cat("sizes disagree with the file length (", strands, " strands, ", vertices, " vertices)"));
    r.values(f.offsets, strands + 1);
    r.values(f.ids, strands);
    r.values(f.positions, vertices);
    r.values(f.radii, vertices);
    if (velocities) r.values(f.velocities, vertices);
    try {
        f.validate();
    } catch (const Error& e) {
        r.fail(std::string("is inconsistent: ") + e.what());
    }
    return out;
}

}  // namespace hp
