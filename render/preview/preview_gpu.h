// GPU resources of the preview (internal to render/preview*.cpp). GL object
// names are plain unsigned ints so this header needs no GL headers.
#pragma once

#include "render/preview/preview.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hp {

/// The per-pass uniform block, std140: mirrors `Frame` in shaders/common.glsl.
struct FrameUniforms {
    float viewProj[16];
    float view[16];
    float lightView[16];  ///< the grid this pass voxelizes (light passes)
    float eye[4];
    float viewport[4];
    float gridMap[4];
    float gridDepth[4];
    float lightVec[16][4];
    float lightRad[16][4];
    float hairColor[4];
    float specColor[4];
    float secondColor[4];
    float hairShape[4];
    float headColor[4];
    float headSkin[4];
    float shadow[4];
    float tess[4];
    float blend[4];
    float gravity[4];
    float wind[4];
    float furTime[4];
    float furLevels[4];
    float lobeShape[4][4];
    float lobeStrength[4 * kHairLobeNodes][4];
    float shadowColor[4];
    float slotClip[kMaxShadowedLights][16];  ///< each shadowed light's grid (LightGrid), for shading
    float slotView[kMaxShadowedLights][16];
    float slotMap[kMaxShadowedLights][4];
    float slotDepth[kMaxShadowedLights][4];
    int counts[4];
    /// The fitted lobes' N(|φ|; |θo|) tables (HairLobe::azimuth), lobe k's
    /// [a][b] at float k·81 + 9a + b (packed four to a vec4).
    float lobeAzimuth[kHairLobeNodes * kHairLobeNodes][4];  // 4 lobes x 81 floats = 81 vec4
};

inline constexpr int kFlagVoxels = 1;
inline constexpr int kFlagShadowMap = 2;
inline constexpr int kFlagVoxelFilter = 4;
/// Some light has no shadow slot: the fitted hair needs slot 0's column for it.
inline constexpr int kFlagUnshadowedLights = 8;
/// Sorted hair: the skin is kept apart and seen through the hair's forward
/// scattering (shaders/resolve.frag), so the shading leaves out the scalp's
/// bounce where the camera sees skin behind the hair.
inline constexpr int kFlagSortedHair = 16;
/// FrameUniforms::counts[3], the hair model (kHair* in shaders/common.glsl).
inline constexpr int kHairKajiyaKay = 0;
inline constexpr int kHairKajiyaKayTwoLobes = 1;
inline constexpr int kHairFitted = 2;
/// Segments per patch when hair is sorted: short enough that a piece of
/// strand rarely straddles another in depth, long enough to keep the
/// per-patch cost of software rasterizers down.
inline constexpr int kSortedPatchSegments = 4;
/// Fixed point of the r32ui voxel grid (kVoxelUnit in shaders/common.glsl).
inline constexpr float kVoxelUnit = 4096.f;

/// What fillFrameUniforms needs besides the uniform block.
struct UniformInputs {
    const View& view;
    const PreviewSettings& settings;
    const PreviewFrame& frame;
    float blendReference = 0.f;            ///< reference depth of the blend weights (m)
    int supersample = 1;
    const std::vector<ShadowSlot>& slots;  ///< the shadowed lights, slot k = slots[k]
    const int* resolutions = nullptr;      ///< voxel resolution of each slot
    bool voxels = false, shadowMap = false;
};

/// What a fibre lets through of the skin behind it besides its gaps, per
/// channel: the fitted hair's forward albedo a_f (Zinke et al. 2008), none
/// for Kajiya-Kay hair (shaders/resolve.frag skinThrough).
Vec3f skinForwardAlbedo(const HairMaterial& hair);

/// The camera pass's uniforms: camera, lights (lightRad[i].w = light i's
/// shadow slot, -1 none), materials, each slot's grid, counts and flags.
void fillFrameUniforms(FrameUniforms& u, const UniformInputs& in);
/// The defines that compile the hair programs for the lights and flags of
/// `u` (shaders/common.glsl HAIR_FLAGS, HAIR_MODEL, shaders/hair_shading.glsl
/// HAIR_LIGHTS): the same shading, with every per-light branch decided at
/// compile time.
std::vector<std::string> hairShadingDefines(const FrameUniforms& u);
/// Points the pass fields (viewProj, lightView, gridMap, gridDepth,
/// viewport) at one slot's grid, for its shadow map and voxelization.
void setPassGrid(FrameUniforms& u, const LightGrid& grid, int resolution);

/// A buffer mapped once for writing and kept mapped (GL 4.4 persistent,
/// coherent mapping): per-frame uploads are a memcpy, and the storage is only
/// reallocated when a frame needs more bytes than any before.
class PersistentBuffer {
  public:
    PersistentBuffer() = default;
    ~PersistentBuffer();
    PersistentBuffer(const PersistentBuffer&) = delete;
    PersistentBuffer& operator=(const PersistentBuffer&) = delete;

    /// Makes room for `bytes`; returns true when the buffer was (re)created.
    bool reserve(size_t bytes);
    void* data() const { return mapped_; }
    unsigned id() const { return id_; }
    size_t capacity() const { return capacity_; }

  private:
    unsigned id_ = 0;
    void* mapped_ = nullptr;
    size_t capacity_ = 0;
};

/// Simulated strands on the GPU: vertices (xyz, radius), the patch index list
/// (a patch per strand, `patchSize` indices each) and each patch's segment
/// count (CPU side, for sorting), rebuilt only when the topology changes.
struct StrandBuffers {
    PersistentBuffer vertices;
    unsigned indices = 0;
    unsigned vao = 0;
    int maxPatchVertices = 32;
    int patchSize = 4;
    std::vector<uint32_t> offsets;  ///< topology of the current index list
    size_t indexCount = 0;
    size_t segments = 0;
    std::vector<uint32_t> list;     ///< the patch index list in strand order
    std::vector<uint32_t> counts;   ///< segments per patch, strand order
    std::vector<uint32_t> sortedList;

    void create();
    void destroy();
    int chunkSegments = 0;          ///< most segments per patch asked for (0: as many as fit)
    /// Uploads the vertices; rebuilds the patches when the topology or
    /// `maxSegments` (segments per patch, 0 = as many as a patch holds) changed.
    void upload(const StrandFrame& strands, int maxSegments = 0);
    /// Reorders the patches back to front along `forward` (the camera's
    /// viewing direction, from `eye`) by the depth of each patch's midpoint,
    /// for blending with the over operator.
    void sortBackToFront(const StrandFrame& strands, const Vec3f& eye, const Vec3f& forward);
};

/// The head mesh (positions + normals interleaved), its triangle list, and the
/// triangles of generated-hair regions with their hair types.
struct HeadBuffers {
    PersistentBuffer vertices;
    unsigned indices = 0;
    unsigned furIndices = 0;
    unsigned furTypes = 0;   ///< SSBO, one uint per region triangle
    unsigned hairTypes = 0;  ///< RGBA32F texture, 2 rows, one column per hair type
    unsigned vao = 0;
    std::vector<uint32_t> triangles;  ///< flattened, for change detection
    std::vector<uint8_t> types;       ///< per triangle hair type of the current fur list
    std::vector<HairType> hairTypeRows;
    size_t indexCount = 0;
    size_t furIndexCount = 0;

    void create();
    void destroy();
    void upload(const TriangleMesh& mesh, const std::vector<uint8_t>& triangleTypes,
                const std::vector<HairType>& hairTypes);
};

/// The camera pass's multisampled target (opaque colour, WBOIT accumulation,
/// revealage, min depth, depth buffer) and the resolved single-sample target.
struct RenderTargets {
    int width = 0, height = 0, samples = 0, supersample = 0;
    unsigned msFbo = 0, opaque = 0, accum = 0, reveal = 0, minDepth = 0, depth = 0;
    unsigned resolvedFbo = 0, resolvedColor = 0, resolvedDepth = 0;
    /// The head's depth from the camera, one sample a pixel (sorted hair:
    /// whether the camera sees skin behind a hair point, shaders/hair_shading.glsl).
    unsigned headFbo = 0, headDepth = 0;

    void ensure(int w, int h, int samples, int supersample);
    void destroy();
    /// The resolved frame as R, G, B, A, Z (top row first).
    Image read() const;
};

static_assert(kMaxShadowedLights == 4, "ShadowTargets::ensure/destroy and shaders/common.glsl spell out 4 slots");

/// Shadow resources of up to kMaxShadowedLights lights (slots): the head's
/// shadow maps (one layer each of a depth array texture), each slot's r32ui
/// voxel grid and the summed R32F grid that the shading samples, and an
/// attachment-less framebuffer for voxelization (its size the largest
/// resolution).
struct ShadowTargets {
    int mapSize = 0, mapLayers = 0, fboSize = 0;
    unsigned map = 0;
    unsigned mapFbo[kMaxShadowedLights] = {};
    unsigned voxelFbo = 0;
    unsigned voxels[kMaxShadowedLights] = {};
    unsigned density[kMaxShadowedLights] = {};
    int resolution[kMaxShadowedLights] = {};  ///< of voxels[k] and density[k]
    unsigned dummyDensity = 0, dummyMap = 0;  ///< bound when a shadow kind is off

    /// Makes `slots` shadow-map layers of mapSize² and a voxel and a density
    /// grid of resolutions[k]³ per slot.
    void ensure(int mapSize, int slots, const int* resolutions);
    void destroy();
    /// Slot k's voxel grid V (grid units / kVoxelUnit) and density C, x fastest, then y, z.
    std::vector<float> readRaw(int k) const;
    std::vector<float> readSummed(int k) const;
};

/// The strands' light-pass pieces captured once by transform feedback
/// (shaders/strand.tese with CAPTURE: world position, tangent, radius, 28
/// bytes a vertex, two vertices a piece) and drawn again as lines for the
/// other lights' voxel grids.
struct CapturedPieces {
    unsigned buffer = 0, feedback = 0, vao = 0;
    size_t capacity = 0;  ///< bytes
    static constexpr size_t kVertexBytes = 28;

    /// Makes room for `vertices` captured vertices.
    void ensure(size_t vertices);
    void destroy();
};

/// Most vertices strand.tesc and strand.tese emit for the patches of
/// `buffers` drawn from a light pass with grid `grid` of `resolution`²
/// raster pixels: per patch, its pieces clamp(ceil(L / pixels), 1, segments
/// level) (L its polyline's raster length; the most when `pixels` <= 0), at
/// least ceil(segments / minSegmentsPerPiece) when that is > 0,
/// plus the rounding of the isolines (at most one piece per 64), two
/// vertices a piece. A bound, never below the count, so the capture buffer
/// never overflows.
size_t lightPieceVertexBound(const StrandBuffers& buffers, const StrandFrame& strands, const LightGrid& grid,
                             int resolution, int level, float pixels, int minSegmentsPerPiece);

/// Whether the ribbon pass can draw anything: true unless every strand vertex
/// lies in front of the camera and is at most `lineWidth` pixels wide there
/// (strand.tesc's THICK_PASS then culls every patch; exact, see the .cpp).
bool mayHaveThickStrands(const StrandFrame& strands, const Mat4f& viewProj, float focalPixels, float lineWidth);

class GlProgram;

/// The strand vertices' radiance, shaded once a frame by a compute pass
/// (shaders/strand_shade.comp) before the camera pass, which interpolates
/// it along each segment (strand.tese with SHADED_POINTS). One RGBA32F
/// texel a vertex, in a buffer texture on unit kUnit.
struct ShadedPoints {
    static constexpr unsigned kUnit = 8;  ///< uPointColor in shaders/strand.tese
    unsigned buffer = 0, texture = 0;
    unsigned flags = 0;   ///< SSBO: a byte a vertex, bit 0 root, bit 1 tip (shaders/strand_shade.comp)
    size_t capacity = 0;  ///< vertices

    /// Shades the vertices of `strands` (as last uploaded) with `program`
    /// (the camera pass's uniforms and shadow textures bound) and binds the
    /// result.
    void shade(const StrandBuffers& strands, const GlProgram& program);
    void destroy();
};

}  // namespace hp
