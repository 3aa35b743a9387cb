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

/// Reads a strand cache, naming the file in every refusal.
ByteReader cacheReader(const std::vector<char>& data, const std::string& file) {
    return ByteReader(data, [file](const std::string& why) { throw AssetError(file, "strand cache " + why); });
}

}  // namespace

void writeStrandCache(const std::filesystem::path& path, const StrandFrame& frame) {
    frame.validate();
    ByteWriter w;
    w.bytes(kMagic, sizeof kMagic);
    w.put(kStrandCacheVersion);
    const bool velocities = !frame.velocities.empty();
    w.put(uint32_t(velocities ? kHasVelocities : 0u));
    w.put(int32_t(frame.frame));
    w.put(uint32_t(frame.guideCount));
    w.put(double(frame.time));
    w.put(uint64_t(frame.strandCount()));
    w.put(uint64_t(frame.vertexCount()));
    w.values(frame.offsets);
    w.values(frame.ids);
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "Vec3f must be packed");
    w.values(frame.positions);
    w.values(frame.radii);
    if (velocities) w.values(frame.velocities);
    w.put(crc32Of(w.data.data(), w.data.size()));

    writeFileChecked(path, w.data.data(), w.data.size());
}

StrandFrame readStrandCache(const std::filesystem::path& path) {
    return parseStrandCache(readFileBytes(path, "strand cache"), path.string());
}

StrandFrame parseStrandCache(const std::vector<char>& data, const std::string& name) {
    ByteReader r = cacheReader(data, name);
    char magic[8];
    r.bytes(magic, sizeof magic);
    if (std::memcmp(magic, kMagic, sizeof magic) != 0) r.fail("has a wrong magic number (not a hairpipe strand cache)");
    const uint32_t version = r.get<uint32_t>();
    if (version != kStrandCacheVersion)
        r.fail(cat("version ", version, " is not supported (this build reads version ", kStrandCacheVersion, ")"));
    if (data.size() < sizeof(uint32_t)) r.fail("truncated");
    uint32_t stored;
    std::memcpy(&stored, data.data() + data.size() - sizeof stored, sizeof stored);
    if (crc32Of(data.data(), data.size() - sizeof stored) != stored)
        r.fail("checksum mismatch: the file is corrupt or was truncated");

    StrandFrame f;
    const uint32_t flags = r.get<uint32_t>();
    f.frame = r.get<int32_t>();
    f.guideCount = r.get<uint32_t>();
    f.time = r.get<double>();
    const uint64_t strands = r.get<uint64_t>();
    const uint64_t vertices = r.get<uint64_t>();
    // Sizes must match the file length exactly before anything is allocated.
    const uint64_t expected = (strands + 1) * 4 + strands * 4 + vertices * (12 + 4) +
                              ((flags & kHasVelocities) ? vertices * 12 : 0) + sizeof(uint32_t);
    if (strands > (1ull << 32) || vertices > (1ull << 32) || expected != r.remaining())
        r.fail(cat("sizes disagree with the file length (", strands, " strands, ", vertices, " vertices)"));
    r.values(f.offsets, strands + 1);
    r.values(f.ids, strands);
    r.values(f.positions, vertices);
    r.values(f.radii, vertices);
    if (flags & kHasVelocities) r.values(f.velocities, vertices);
    try {
        f.validate();
    } catch (const Error& e) {
        r.fail(std::string("is inconsistent: ") + e.what());
    }
    return f;
}

}  // namespace hp
