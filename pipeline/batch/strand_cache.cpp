#include "pipeline/batch/strand_cache.h"

#include "core/errors.h"
#include "core/files.h"
#include "sim/solver/state_blob.h"

#include <zlib.h>

#include <cstring>
#include <fstream>
#include <limits>

namespace hp {

namespace {

constexpr char kMagic[8] = {'H', 'P', 'S', 'T', 'R', 'A', 'N', 'D'};
constexpr uint32_t kHasVelocities = 1u;

/// The strand cache's reader: a malformed file is an AssetError naming it.
class CacheReader final : public BlobReader {
  public:
    CacheReader(const std::vector<char>& data, const std::string& file) : BlobReader(data, file), file_(file) {}
    [[noreturn]] void fail(const std::string& why) const override { throw AssetError(file_, "strand cache " + why); }

  private:
    std::string file_;
};

uint32_t crc(const char* data, size_t n) {
    uLong c = crc32(0L, Z_NULL, 0);
    // zlib takes uInt lengths: feed large buffers in pieces.
    while (n > 0) {
        const uInt chunk = uInt(std::min<size_t>(n, std::numeric_limits<uInt>::max()));
        c = crc32(c, reinterpret_cast<const Bytef*>(data), chunk);
        data += chunk;
        n -= chunk;
    }
    return uint32_t(c);
}

}  // namespace

void writeStrandCache(const std::filesystem::path& path, const StrandFrame& frame) {
    frame.validate();
    BlobWriter w;
    w.bytes(kMagic, sizeof kMagic);
    w.put(kStrandCacheVersion);
    const bool velocities = !frame.velocities.empty();
    w.put(uint32_t(velocities ? kHasVelocities : 0u));
    w.put(int32_t(frame.frame));
    w.put(uint32_t(frame.guideCount));
    w.put(double(frame.time));
    w.put(uint64_t(frame.strandCount()));
    w.put(uint64_t(frame.vertexCount()));
    w.raw(frame.offsets);
    w.raw(frame.ids);
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "Vec3f must be packed");
    w.raw(frame.positions);
    w.raw(frame.radii);
    if (velocities) w.raw(frame.velocities);
    w.put(crc(w.data.data(), w.data.size()));

    writeFileChecked(path, w.data.data(), w.data.size());
}

StrandFrame readStrandCache(const std::filesystem::path& path) {
    return parseStrandCache(readFileBytes(path, "strand cache"), path.string());
}

StrandFrame parseStrandCache(const std::vector<char>& data, const std::string& name) {
    CacheReader r(data, name);
    char magic[8];
    r.bytes(magic, sizeof magic);
    if (std::memcmp(magic, kMagic, sizeof magic) != 0) r.fail("has a wrong magic number (not a hairpipe strand cache)");
    const uint32_t version = r.get<uint32_t>();
    if (version != kStrandCacheVersion)
        r.fail(cat("version ", version, " is not supported (this build reads version ", kStrandCacheVersion, ")"));
    if (data.size() < sizeof(uint32_t)) r.fail("truncated");
    uint32_t stored;
    std::memcpy(&stored, data.data() + data.size() - sizeof stored, sizeof stored);
    if (crc(data.data(), data.size() - sizeof stored) != stored)
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
    r.raw(f.offsets, strands + 1);
    r.raw(f.ids, strands);
    r.raw(f.positions, vertices);
    r.raw(f.radii, vertices);
    if (flags & kHasVelocities) r.raw(f.velocities, vertices);
    try {
        f.validate();
    } catch (const Error& e) {
        r.fail(std::string("is inconsistent: ") + e.what());
    }
    return f;
}

}  // namespace hp
