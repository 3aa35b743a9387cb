// The one translation unit that includes OpenVDB (see render/volume/vdb_writer.h).
#include "render/volume/vdb_writer.h"

#include "core/errors.h"

#include <Eigen/LU>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Prune.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <streambuf>
#include <string>
#include <mutex>

namespace hp {

namespace {

void initializeOpenVdb() {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

/// A 128-bit digest of what a file holds, independent of the order its parts
/// are added in (parts are hashed on their own and summed per lane), so
/// blocks hashed in parallel combine deterministically. Non-cryptographic:
/// it identifies contents, nothing more.
class Digest {
  public:
    void add(const void* data, size_t size, uint64_t seed) {
        uint64_t h1 = 0x9E3779B97F4A7C15ull ^ seed, h2 = 0xC2B2AE3D27D4EB4Full + seed;
        const auto* bytes = static_cast<const unsigned char*>(data);
        size_t i = 0;
        for (; i + 8 <= size; i += 8) {
            uint64_t w;
            std::memcpy(&w, bytes + i, 8);
            h1 = (h1 ^ w) * 0x100000001B3ull;
            h1 ^= h1 >> 29;
            h2 = (h2 ^ (w + 0x632BE59BD9B4E019ull)) * 0xFF51AFD7ED558CCDull;
            h2 ^= h2 >> 32;
        }
        for (; i < size; ++i) {
            h1 = (h1 ^ bytes[i]) * 0x100000001B3ull;
            h2 = (h2 ^ bytes[i]) * 0xFF51AFD7ED558CCDull;
        }
        h1 = (h1 ^ size) * 0xC4CEB9FE1A85EC53ull;
        h2 = (h2 ^ (h1 >> 31)) * 0x9E3779B97F4A7C15ull;
        lane1_.fetch_add(h1, std::memory_order_relaxed);
        lane2_.fetch_add(h2 ^ (h2 >> 29), std::memory_order_relaxed);
    }
    void add(const std::string& text, uint64_t seed) { add(text.data(), text.size(), seed); }

    /// As a UUID string (RFC 9562 layout, version 8 "custom", RFC variant).
    std::string uuid() const {
        uint64_t h1 = lane1_.load(), h2 = lane2_.load();
        h1 = (h1 & ~(0xFull << 12)) | (0x8ull << 12);
        h2 = (h2 & ~(0x3ull << 62)) | (0x2ull << 62);
        char text[37];
        std::snprintf(text, sizeof text, "%08x-%04x-%04x-%04x-%012llx", unsigned(h1 >> 32),
                      unsigned((h1 >> 16) & 0xFFFF), unsigned(h1 & 0xFFFF), unsigned(h2 >> 48),
                      (unsigned long long)(h2 & 0xFFFFFFFFFFFFull));
        return text;
    }

  private:
    std::atomic<uint64_t> lane1_{0}, lane2_{0};
};

/// OpenVDB writes a random UUID into the file header (36 ASCII characters
/// after magic, format version, library version and a flag: bytes 21..56).
/// Replace it by the digest of the file's contents, so the same grid makes
/// the same bytes (resume checks, caches and diffs see no change).
void writeHeaderUuid(const std::filesystem::path& file, const std::string& uuid) {
    constexpr size_t kUuidOffset = 8 + 4 + 4 + 4 + 1, kUuidSize = 36;
    std::fstream io(file, std::ios::in | std::ios::out | std::ios::binary);
    char header[kUuidOffset + kUuidSize];
    if (!io || !io.read(header, sizeof header)) throw IoError(file.string(), "cannot reopen the written VDB file");
    int64_t magic = 0;
    std::memcpy(&magic, header, sizeof magic);
    if (magic != openvdb::OPENVDB_MAGIC || header[kUuidOffset + 8] != '-' || uuid.size() != kUuidSize)
        throw IoError(file.string(), "unexpected VDB header layout (OpenVDB version changed?)");
    io.seekp(std::streamoff(kUuidOffset));
    io.write(uuid.data(), std::streamsize(kUuidSize));
    io.flush();
    if (!io) throw IoError(file.string(), "cannot rewrite the VDB header");
}

/// OpenVDB's io::File::write opens its own std::ofstream and never looks at
/// it again, so a full disk leaves a truncated file and no error (and the
/// atomic rename would publish it). Archive's stream writer is protected:
/// this subclass hands it a stream the caller owns and checks once closed.
/// Same bytes as io::File (seekable stream, same header and compression).
class CheckedVdbArchive final : public openvdb::io::Archive {
  public:
    void writeTo(std::ostream& os, const openvdb::GridPtrVec& grids) const { Archive::write(os, grids, true); }
};

/// OpenVDB's Mat4 is row-vector (p' = p · M, translation in the last row).
openvdb::math::Mat4d toVdbMatrix(const GridTransform& t) {
    const Eigen::Matrix3d a = t.indexToWorld();
    const Vec3d translation = -(a * t.offset);
    openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) m(r, c) = a(c, r);
    for (int c = 0; c < 3; ++c) m(3, c) = translation[c];
    return m;
}

openvdb::math::Transform::Ptr toVdbTransform(const GridTransform& t) {
    const double h = t.uniformVoxelSize();
    if (h > 0 && t.offset.isZero(0.0)) return openvdb::math::Transform::createLinearTransform(h);
    return openvdb::math::Transform::createLinearTransform(toVdbMatrix(t));
}

/// Fills the density tree (values × scale) and, if given, the velocity tree
/// from the grid's blocks, adding each block to `digest`. Blocks and OpenVDB
/// leaves are both 8³ in x-major order, so each block becomes one leaf: the
/// leaves are allocated and filled in parallel, then attached to the tree
/// serially (topology changes are not thread-safe; addLeaf only links a
/// pointer, where touchLeaf also allocated and cleared the leaf on that one
/// thread). With `consume`, each block is freed once copied, so the grid
/// and the trees are not both whole in memory.
void fillTrees(openvdb::FloatTree& densityTree, openvdb::Vec3STree* velocityTree, const DensityGrid& grid,
               float scale, DensityGrid* consume, Digest* digest) {
    using DensityLeaf = openvdb::FloatTree::LeafNodeType;
    using VelocityLeaf = openvdb::Vec3STree::LeafNodeType;
    static_assert(DensityLeaf::DIM == DensityGrid::kBlockSize, "DensityGrid blocks must match OpenVDB leaves");
    // In batches, so that with `consume` the memory freed by one batch's
    // blocks holds the next batch's leaves.
    constexpr size_t kBatch = 4096;
    std::vector<std::unique_ptr<DensityLeaf>> densityLeaves(kBatch);
    std::vector<std::unique_ptr<VelocityLeaf>> velocityLeaves(kBatch);
    for (size_t first = 0; first < grid.blockCount(); first += kBatch) {
        const size_t count = std::min(kBatch, grid.blockCount() - first);
        tbb::parallel_for(size_t(0), count, [&](size_t i) {
            const size_t b = first + i;
            const Vec3i& o = grid.blockOrigin(b);
            const openvdb::Coord origin(o.x(), o.y(), o.z());
            // PartialCreate: the buffer is allocated by data() below without
            // being cleared first (every value is written).
            densityLeaves[i] = std::make_unique<DensityLeaf>(openvdb::PartialCreate(), origin, 0.f, false);
            const float* density = grid.blockDensity(b);
            // Whole buffers and 64-bit mask words: inactive voxels hold the
            // background 0, as the block does.
            float* values = densityLeaves[i]->buffer().data();
            auto& mask = densityLeaves[i]->getValueMask();
            for (openvdb::Index w = 0; w < openvdb::Index(DensityGrid::kBlockVoxels / 64); ++w) {
                uint64_t bits = 0;
                for (int j = 0; j < 64; ++j) {
                    const float d = density[w * 64 + openvdb::Index(j)];
                    values[w * 64 + openvdb::Index(j)] = d * scale;
                    bits |= uint64_t(d > 0.f) << j;
                }
                mask.getWord<uint64_t>(w) = bits;
            }
            if (velocityTree) {
                velocityLeaves[i] = std::make_unique<VelocityLeaf>(openvdb::PartialCreate(), origin, openvdb::Vec3s(0.f), false);
                const Vec3f* velocity = grid.blockVelocity(b);
                openvdb::Vec3s* vvalues = velocityLeaves[i]->buffer().data();
                for (int v = 0; v < DensityGrid::kBlockVoxels; ++v)
                    vvalues[v] = openvdb::Vec3s(velocity[v].x(), velocity[v].y(), velocity[v].z());
                velocityLeaves[i]->getValueMask() = mask;
            }
            const uint64_t seed = (uint64_t(uint32_t(o.x())) << 42) ^ (uint64_t(uint32_t(o.y())) << 21) ^ uint32_t(o.z());
            digest->add(density, sizeof(float) * DensityGrid::kBlockVoxels, seed);
            if (velocityTree) digest->add(grid.blockVelocity(b), sizeof(Vec3f) * DensityGrid::kBlockVoxels, ~seed);
            if (consume) consume->releaseBlock(b);
        });
        for (size_t i = 0; i < count; ++i) {
            densityTree.addLeaf(densityLeaves[i].release());
            if (velocityTree) velocityTree->addLeaf(velocityLeaves[i].release());
        }
    }
    openvdb::tools::pruneInactive(densityTree);
    if (velocityTree) openvdb::tools::pruneInactive(*velocityTree);
}

/// A stream buffer that appends to a string: one chunk of leaves serialized in memory.
class StringBuffer final : public std::streambuf {
  public:
    std::string bytes;

  protected:
    std::streamsize xsputn(const char* s, std::streamsize n) override {
        bytes.append(s, size_t(n));
        return n;
    }
    int_type overflow(int_type c) override {
        if (!traits_type::eq_int_type(c, traits_type::eof())) bytes.push_back(traits_type::to_char_type(c));
        return traits_type::not_eof(c);
    }
};

/// An OpenVDB grid whose buffers (the leaves' values: nearly all of the
/// file) are serialized in parallel. Grid::writeBuffers streams the leaves
/// one after the other in the tree's depth-first order, each by
/// LeafNode::writeBuffers (value mask, then the values: active-mask
/// compression, half conversion, Blosc), all on the archive's one thread.
/// Here chunks of leaves in that same order go through the same
/// LeafNode::writeBuffers into memory streams on TBB's threads and are then
/// written in order: the same bytes (VdbFile.ParallelLeafBuffersGiveOpenVdbsSerialBytes).
/// Each chunk's stream takes the archive stream's format state (copyfmt):
/// OpenVDB keeps the compression flags, the background value and the stream
/// metadata in iword/pword slots, which LeafNode::writeBuffers reads.
template <typename GridT>
class ParallelBuffersGrid final : public GridT {
  public:
    using GridT::GridT;
    using Ptr = std::shared_ptr<ParallelBuffersGrid>;

    void writeBuffers(std::ostream& os) const override {
        if (GridT::hasMultiPassIO()) {  // point grids: passes over the whole tree
            GridT::writeBuffers(os);
            return;
        }
        using LeafT = typename GridT::TreeType::LeafNodeType;
        std::vector<const LeafT*> leaves;
        leaves.reserve(this->tree().leafCount());
        this->tree().getNodes(leaves);  // depth-first, the order of Tree::writeBuffers
        const bool toHalf = this->saveFloatAsHalf();
        // Rounds of chunks, so at most a round's bytes (~8 MiB of half
        // values) wait in memory before the archive's stream takes them.
        constexpr size_t kChunk = 256, kChunksPerRound = 32;
        std::vector<std::string> chunks(kChunksPerRound);
        for (size_t first = 0; first < leaves.size(); first += kChunk * kChunksPerRound) {
            const size_t end = std::min(leaves.size(), first + kChunk * kChunksPerRound);
            const size_t count = (end - first + kChunk - 1) / kChunk;
            tbb::parallel_for(size_t(0), count, [&](size_t c) {
                StringBuffer buffer;
                buffer.bytes.reserve(kChunk * (sizeof(typename LeafT::ValueType) * LeafT::SIZE + 80));
                std::ostream chunk(&buffer);
                chunk.copyfmt(os);
                const size_t from = first + c * kChunk, to = std::min(end, from + kChunk);
                for (size_t i = from; i < to; ++i) leaves[i]->writeBuffers(chunk, toHalf);
                if (!chunk) throw openvdb::IoError("cannot serialize leaf buffers in memory");
                chunks[c] = std::move(buffer.bytes);
            });
            for (size_t c = 0; c < count; ++c) os.write(chunks[c].data(), std::streamsize(chunks[c].size()));
        }
    }
};

using DensityVdbGrid = ParallelBuffersGrid<openvdb::FloatGrid>;
using VelocityVdbGrid = ParallelBuffersGrid<openvdb::Vec3SGrid>;

}  // namespace

namespace {

void writeGrids(const std::filesystem::path& file, const DensityGrid& grid, const VdbFrameInfo& info,
                const VdbWriteSettings& settings, DensityGrid* consume) {
    initializeOpenVdb();
    const openvdb::math::Transform::Ptr transform = toVdbTransform(grid.transform());
    const float scale = float(settings.densityScale);

    auto density = std::make_shared<DensityVdbGrid>(0.f);
    density->setName("density");
    density->setGridClass(openvdb::GRID_FOG_VOLUME);
    density->setTransform(transform);
    density->setSaveFloatAsHalf(settings.halfFloat);
    density->setCreator("hairpipe");

    const double h = grid.transform().uniformVoxelSize();
    density->insertMeta("frame", openvdb::Int32Metadata(info.frame));
    density->insertMeta("time", openvdb::DoubleMetadata(info.time));
    density->insertMeta("fps", openvdb::DoubleMetadata(info.fps));
    density->insertMeta("scene", openvdb::StringMetadata(info.scene));
    density->insertMeta("units", openvdb::StringMetadata(
                                     "density: hair volume fraction (m^3 of hair per m^3) x density_scale; "
                                     "lengths: metres; world space, Y up"));
    density->insertMeta("voxel_size", openvdb::DoubleMetadata(h > 0 ? h : std::cbrt(grid.transform().voxelVolume())));
    density->insertMeta("strand_count", openvdb::Int64Metadata(int64_t(info.strandCount)));
    density->insertMeta("hair_volume", openvdb::DoubleMetadata(info.hairVolume));
    density->insertMeta("filter", openvdb::StringMetadata(info.filter));
    density->insertMeta("density_scale", openvdb::DoubleMetadata(settings.densityScale));

    openvdb::GridPtrVec grids{density};
    VelocityVdbGrid::Ptr velocity;
    if (settings.velocity && grid.hasVelocity()) {
        velocity = std::make_shared<VelocityVdbGrid>(openvdb::Vec3s(0.f));
        velocity->setName("velocity");
        velocity->setTransform(transform);
        velocity->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
        velocity->setSaveFloatAsHalf(settings.halfFloat);
        velocity->setCreator("hairpipe");
        velocity->insertMeta("units", openvdb::StringMetadata("m/s, density-weighted mean velocity of the hair"));
        velocity->insertMeta("frame", openvdb::Int32Metadata(info.frame));
        grids.push_back(velocity);
    }
    Digest digest;
    fillTrees(density->tree(), velocity ? &velocity->tree() : nullptr, grid, scale, consume, &digest);
    if (consume) consume->clear();
    // Everything else that shapes the bytes: metadata, transform, options, library.
    for (const openvdb::GridBase::Ptr& g : grids) digest.add(g->str() + g->transform().baseMap()->str(), 1);
    digest.add(cat(settings.halfFloat, int(settings.compression), openvdb::getLibraryVersionString(),
                   openvdb::OPENVDB_FILE_VERSION),
               2);
    const double exact[] = {info.time, info.fps, info.hairVolume, settings.densityScale};  // text rounds them
    digest.add(exact, sizeof exact, 3);

    try {
        CheckedVdbArchive archive;
        uint32_t flags = openvdb::io::COMPRESS_ACTIVE_MASK;
        if (settings.compression == VdbCompression::Blosc) {
            if (!openvdb::io::Archive::hasBloscCompression())
                throw IoError(file.string(), "this OpenVDB library was built without Blosc; use compression: none");
            flags |= openvdb::io::COMPRESS_BLOSC;
        }
        archive.setCompression(flags);
        // OpenVDB writes each leaf (about 2 KiB) on its own; with the stream's
        // default 8 KiB buffer that is one write() system call every few
        // leaves. A 4 MiB buffer makes it one every ~2000 leaves.
        std::vector<char> buffer(size_t(4) << 20);
        std::ofstream out;
        out.rdbuf()->pubsetbuf(buffer.data(), std::streamsize(buffer.size()));  // before open (libstdc++)
        out.open(file, std::ios::binary | std::ios::trunc);
        if (!out) throw IoError(file.string(), cat("cannot create the file: ", std::strerror(errno)));
        archive.writeTo(out, grids);
        out.close();  // flushes: a full disk may show only here
        if (!out) throw IoError(file.string(), "write failed (disk full?)");
    } catch (const openvdb::Exception& e) {
        throw IoError(file.string(), std::string("OpenVDB: ") + e.what());
    }
    writeHeaderUuid(file, digest.uuid());
}

}  // namespace

void writeDensityVdb(const std::filesystem::path& file, const DensityGrid& grid, const VdbFrameInfo& info,
                     const VdbWriteSettings& settings) {
    writeGrids(file, grid, info, settings, nullptr);
}

void writeDensityVdb(const std::filesystem::path& file, DensityGrid&& grid, const VdbFrameInfo& info,
                     const VdbWriteSettings& settings) {
    writeGrids(file, grid, info, settings, &grid);
}

// ---------------------------------------------------------------------------
// Reader

namespace {

GridTransform fromVdbTransform(const openvdb::math::Transform& t) {
    const openvdb::math::Mat4d m = t.baseMap()->getAffineMap()->getMat4();
    Eigen::Matrix3d a;
    Vec3d translation;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) a(c, r) = m(r, c);
    for (int c = 0; c < 3; ++c) translation[c] = m(3, c);
    GridTransform g;
    g.linear = a.inverse();
    g.offset = -(g.linear * translation);
    return g;
}

VdbGridInfo describe(const openvdb::GridBase& grid) {
    VdbGridInfo info;
    info.name = grid.getName();
    info.valueType = grid.valueType();
    info.gridClass = openvdb::GridBase::gridClassToString(grid.getGridClass());
    info.vectorType = openvdb::GridBase::vecTypeToString(grid.getVectorType());
    info.savedAsHalf = grid.saveFloatAsHalf();
    const openvdb::math::Mat4d m = grid.transform().baseMap()->getAffineMap()->getMat4();
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) info.indexToWorld(c, r) = m(r, c);
    const openvdb::Vec3d size = grid.transform().voxelSize();
    if (std::abs(size[0] - size[1]) <= 1e-9 * size[0] && std::abs(size[0] - size[2]) <= 1e-9 * size[0])
        info.voxelSize = size[0];
    info.activeVoxels = size_t(grid.activeVoxelCount());
    const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    if (!box.empty()) {
        info.activeMin = Vec3i(box.min().x(), box.min().y(), box.min().z());
        info.activeMax = Vec3i(box.max().x(), box.max().y(), box.max().z());
    }
    for (auto it = grid.beginMeta(); it != grid.endMeta(); ++it) {
        info.metadata[it->first] = it->second->str();
        info.metadataType[it->first] = it->second->typeName();
    }
    return info;
}

}  // namespace

VdbContents readDensityVdb(const std::filesystem::path& file) {
    initializeOpenVdb();
    VdbContents contents;
    try {
        openvdb::io::File in(file.string());
        in.open(/*delayLoad=*/false);
        openvdb::FloatGrid::Ptr density;
        openvdb::Vec3SGrid::Ptr velocity;
        for (auto name = in.beginName(); name != in.endName(); ++name) {
            openvdb::GridBase::Ptr grid = in.readGrid(name.gridName());
            VdbGridInfo info = describe(*grid);
            if (auto g = openvdb::gridPtrCast<openvdb::FloatGrid>(grid)) {
                info.background = g->background();
                if (info.name == "density") density = g;
            }
            if (auto g = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grid))
                if (info.name == "velocity") velocity = g;
            contents.grids.push_back(std::move(info));
        }
        in.close();
        if (density) {
            std::vector<Vec3i> origins;
            std::vector<DensityGrid::DensityBlockPtr> values;
            std::vector<DensityGrid::VelocityBlockPtr> velocities;
            for (auto leaf = density->tree().cbeginLeaf(); leaf; ++leaf) {
                const openvdb::Coord o = leaf->origin();
                origins.emplace_back(o.x(), o.y(), o.z());
                values.push_back(std::make_unique<DensityGrid::DensityBlock>());
                values.back()->fill(0.f);
                for (auto v = leaf->cbeginValueOn(); v; ++v) (*values.back())[v.pos()] = *v;
                if (velocity) {
                    velocities.push_back(std::make_unique<DensityGrid::VelocityBlock>());
                    velocities.back()->fill(Vec3f::Zero());
                    if (const auto* vleaf = velocity->tree().probeConstLeaf(o))
                        for (auto v = vleaf->cbeginValueOn(); v; ++v)
                            (*velocities.back())[v.pos()] = Vec3f((*v)[0], (*v)[1], (*v)[2]);
                }
            }
            contents.density = DensityGrid(fromVdbTransform(density->transform()), std::move(origins),
                                           std::move(values), std::move(velocities));
            contents.hasDensity = true;
        }
    } catch (const openvdb::Exception& e) {
        throw AssetError(file.string(), std::string("cannot read VDB file: ") + e.what());
    }
    return contents;
}

}  // namespace hp
