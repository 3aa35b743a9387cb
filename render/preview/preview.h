// The real-time preview pass (Dehlin and Styngberg 2017): strands and generated hair drawn with
// OpenGL 4.5 core — isoline tessellation, camera-facing ribbons, Kajiya-Kay
// shading, voxel self-shadows plus a PCF shadow map of the head — into an
// offscreen multisampled framebuffer, read back as an Image.
//
// How hair is drawn (shaders/ holds the GLSL):
// - Strand polylines are uploaded to persistently mapped buffers (reallocated
//   only when a frame has more vertices than any before) and drawn as one
//   patch per strand (the per-patch cost dominates on llvmpipe). An isoline
//   tessellation stage smooths them — uniform Catmull-Rom through the
//   vertices or a uniform cubic B-spline; mirrored end points make both reach
//   the root and tip — cut into about screen length / `tessellationPixels`
//   pieces per strand (at most `tessellationLevel` per segment).
// - Strands at least `minPixelWidth` wide somewhere become camera-facing
//   ribbons in a geometry shader, 2r wide (r interpolated along the strand).
//   Thinner hair would alias away, so it is drawn `minPixelWidth` wide with
//   alpha = true width / drawn width, which keeps its expected coverage equal
//   to its projected area; with MSAA such strands are drawn as multisampled
//   lines of that width (exact rectangles per the GL spec, one primitive per
//   piece instead of a ribbon's two: ~1.5x faster on llvmpipe). Multisampling
//   (and optional supersampling) antialiases the edges.
// - Shading (Kajiya-Kay, mirroring kajiyaKay() in render/view/view.cpp, times each
//   light's visibility) runs per tessellated strand point by default and is
//   interpolated along the strand, or per fragment (`shadePerFragment`).
// - Hair is semi-transparent. Sorted (default): strands are cut into pieces
//   of 4 segments (one patch each), sorted back to front from the camera
//   every frame (by their midpoint depth) and blended with the over operator
//   onto the opaque head: what a ray tracer sees (the nearest strand hides
//   what is behind it in proportion to its coverage), up to pieces that
//   overlap in depth. Generated hair is blended after them, unsorted. Weighted:
//   weighted blended order-independent transparency (McGuire & Bavoil 2013):
//   alpha is exact (1 - prod(1 - a_i)), colour a weighted mean favouring
//   fragments nearer than the scene's front by `blendDepthScale` metres,
//   which lets hair deep in the volume tint the front (unsorted, cheaper).
//   Opaque head fragments hide the hair behind them through the depth test.
// - Shadows of up to kMaxShadowedLights lights, each on its own: the hair
//   voxelized from that light into an r32ui 3D texture with image atomics
//   (Dehlin and Styngberg's binary/additive, nearest/trilinear), summed along
//   the light in a compute pass into the light's density grid, transmittance
//   alpha^C; times a PCF shadow map of the head from that light. On a
//   software renderer the same grids are filled and summed on the CPU
//   (render/preview/cpu_voxels.h, PreviewShadowSettings::voxelize). Point lights
//   use a perspective frustum. The strands are tessellated once for all the
//   lights (from the first; the pieces captured by transform feedback and
//   drawn again as lines from the others' views).
// - Output: R, G, B premultiplied linear radiance (the environment colour
//   fills what coverage leaves), A the coverage of hair and head, Z the
//   camera-space depth in metres (distance along the view axis, not along
//   the ray) of the nearest fragment of any opacity; +inf where empty.
#pragma once

#include "render/preview/generated_hair.h"
#include "render/image/image_io.h"
#include "render/preview/light_grid.h"
#include "render/view/view.h"
#include "sim/strands/head.h"
#include "sim/strands/strand.h"

#include <memory>
#include <string>
#include <vector>

namespace hp {

enum class CurveType { CatmullRom, BSpline };
/// Dehlin and Styngberg 2017's voxel update: occupancy (set to 1) or density (add 1 per fragment).
enum class VoxelMode { Binary, Additive };
/// How semi-transparent hair is composited (see the file comment).
enum class HairBlend { Sorted, Weighted };
/// Dehlin and Styngberg 2017's splatting of a fragment into the grid: its voxel, or trilinear
/// weights over the 8 nearest voxel centres (additive only).
enum class VoxelSplat { Nearest, Trilinear };
/// What a voxel counts: expected strand crossings of a light ray (each
/// fragment weighted by its strand's projected area in the voxel's column),
/// or fragments (Dehlin and Styngberg 2017: each fragment adds 1, whatever the hair's width).
enum class VoxelWeight { Crossings, Fragments };
/// Where the strands are voxelized for the light grids: on the CPU
/// (render/preview/cpu_voxels.h, the same grid), or by the GPU's rasterizer;
/// Auto: the CPU on a software renderer (llvmpipe), the GPU otherwise.
enum class VoxelizeOn { Auto, Gpu, Cpu };

/// Most lights the preview shadows: each costs a voxelization of the hair, a
/// sum along its light, a shadow map and a density grid (render/preview/
/// preview_gpu.h); the default three-point rig needs three.
inline constexpr int kMaxShadowedLights = 4;

/// Shadows of the shadowed lights: the lights with Light::castsShadows, the
/// first `maxLights` of them in View::lights order (others are unshadowed,
/// and the pipeline marks them so, for the Kajiya-Kay reference to agree).
/// Each gets its own LightGrid, voxel density and head shadow map.
struct PreviewShadowSettings {
    int maxLights = kMaxShadowedLights;  ///< 0..kMaxShadowedLights; 0 = no shadows
    bool voxels = true;           ///< hair self-shadowing through the voxel grid
    VoxelMode mode = VoxelMode::Additive;
    VoxelSplat splat = VoxelSplat::Nearest;
    /// Sum the grid along the light (Dehlin and Styngberg's C); false shades with the raw
    /// voxel value V, Dehlin and Styngberg's visualisation of the voxelization itself.
    bool sumAlongLight = true;
    int resolution = 256;         ///< voxels along each axis of the first shadowed light's box
    /// The same for the other shadowed lights (fill, rim); 0 = `resolution`.
    /// Coarser: their grids cost an eighth to clear and sum (docs/rendering.md).
    int otherResolution = 128;
    /// Average C over 2 x 2 voxels across the beam at lookup: hides the moire
    /// rings regularly spaced hair casts through one-voxel-wide lines.
    bool filter = true;
    /// Crossings (default): C is the number of strand crossings a light ray
    /// expects in front of a point (Additive; Binary: each occupied voxel
    /// counts as one crossing of its widest strand), and light reaching the
    /// point is exp(-(1 - T) C) with T = View::hair.transmittance, the
    /// reference renderer's per-crossing transmittance: both renderers derive
    /// hair shadows from that one parameter. Fragments: Dehlin and Styngberg's count,
    /// light = alpha^C with the `alpha` below.
    VoxelWeight weight = VoxelWeight::Crossings;
    /// Fragments only: transmittance per counted fragment (or occupied voxel).
    float alpha = 0.85f;
    VoxelizeOn voxelize = VoxelizeOn::Auto;
    /// With several shadowed lights, tessellate the strands once, from the
    /// first shadowed light, capture the pieces (transform feedback) and
    /// voxelize that geometry into every light's grid; false tessellates the
    /// strands again from each light (pieces of `tessellationPixels` in each
    /// light's own raster). The first light's grid is the same either way.
    bool shareTessellation = true;
    bool shadowMap = true;        ///< PCF shadow map of the opaque head (hair and head receive it)
    int shadowMapSize = 2048;
    int pcfRadius = 1;            ///< (2r+1)^2 bilinear comparisons (seed eq. 8)
};

struct PreviewSettings {
    int msaa = 4;                 ///< samples per pixel (clamped to what the driver offers)
    int supersample = 1;          ///< render at N x N the resolution and average
    CurveType curve = CurveType::CatmullRom;
    int tessellationLevel = 8;    ///< most pieces per strand segment (1..64)
    float tessellationPixels = 20.f;  ///< target on-screen length of a piece; 0 = always the most
    float minPixelWidth = 1.f;    ///< thinnest ribbon drawn (output pixels); alpha scales coverage below
    HairBlend blend = HairBlend::Sorted;
    float blendDepthScale = 0.02f;   ///< Weighted: metres; smaller = nearer hair dominates more
    /// Shade hair per fragment instead of per ribbon vertex (tessellated
    /// piece end). Per vertex is several times faster on llvmpipe; per
    /// fragment resolves sharp highlights and shadow edges along a strand.
    bool shadePerFragment = false;
    /// Per-vertex shading in a compute pass, once per strand vertex, which
    /// the tessellation interpolates along each segment (llvmpipe runs
    /// compute on all its threads, the tessellation stages on one); false:
    /// shade every tessellated point in the tessellation stage. Off by
    /// default: on 2 cores it saves 2 % of a 1080p frame's CPU and costs 10 %
    /// of a 560 x 720 one, whose pieces span several vertices
    /// (docs/benchmarks.md).
    bool shadeInCompute = false;
    /// The thin strands' line pieces (per-vertex shading, the line path):
    /// made by compute passes and drawn as plain lines (1), or by the
    /// tessellation stages (0); -1: compute on software rasterizers, which
    /// run the tessellation stages on one thread (render/preview/line_pieces.h).
    /// The same pieces and shading: pixels agree to FLIP ~1e-4.
    int piecesInCompute = -1;
    /// Compile the hair programs for each frame's lights, flags and hair
    /// model (llvmpipe pays both sides of a branch on a uniform); false: one
    /// program that reads them from uniforms (the same pixels; tests).
    bool specializeShading = true;
    PreviewShadowSettings shadow;
    GeneratedHairSettings generated;
    bool drawHead = true;
    bool drawStrands = true;
    /// Finish each pass before the next and time it (PreviewStats::passes):
    /// for benchmarks; slows drawing down.
    bool profile = false;
};

/// What one frame draws; any pointer may be null.
struct PreviewFrame {
    double time = 0.0;                      ///< seconds (animates the generated hair's wind)
    const StrandFrame* strands = nullptr;
    const TriangleMesh* head = nullptr;     ///< world space; normals computed when missing
    /// Head pose for generated hair regions (world -> rest is its inverse).
    Eigen::Isometry3f headTransform = Eigen::Isometry3f::Identity();
    const std::vector<uint8_t>* scalpMask = nullptr;  ///< per head triangle, for Mask regions
};

/// Counters of the last draw (GL queries), for tests and the viewer.
struct PreviewStats {
    size_t strandSegments = 0;     ///< simulated strand segments uploaded
    size_t furTriangles = 0;       ///< head triangles in generated-hair regions
    size_t generatedStrands = 0;   ///< strands grown by the geometry shader (camera pass)
    bool shadowed = false;         ///< at least one light is shadowed
    int shadowedLights = 0;        ///< lights with a light grid this frame
    std::string renderer;          ///< GL_RENDERER
    /// With PreviewSettings::profile: (pass, wall ms, process CPU ms, CPU ms
    /// of the calling thread) in order. On llvmpipe the calling thread runs
    /// the vertex, tessellation and geometry shaders (Mesa's draw module) and
    /// its rasterizer threads the fragments, so threadMs is the serial part.
    struct Pass {
        std::string name;
        double wallMs = 0.0, cpuMs = 0.0, threadMs = 0.0;
    };
    std::vector<Pass> passes;
};

/// The shadow grid after the last draw: raw voxel values V and the summed C
/// the shading reads (both in strand crossings, or fragments with
/// VoxelWeight::Fragments), plus the mapping.
struct VoxelSnapshot {
    int resolution = 0;
    LightGrid grid;
    std::vector<float> raw;      ///< V, x fastest, then y, then z (light depth)
    std::vector<float> summed;   ///< C at each voxel centre (exclusive: what lies strictly in front)
    float rawAt(int x, int y, int z) const { return raw[(size_t(z) * resolution + y) * resolution + x]; }
    float summedAt(int x, int y, int z) const { return summed[(size_t(z) * resolution + y) * resolution + x]; }
};

class PreviewRenderer {
  public:
    /// Needs a current OpenGL 4.5 core context (GlContext, or a viewer
    /// window); compiles and links every program. Throws hp::Error.
    explicit PreviewRenderer(const PreviewSettings& settings);
    ~PreviewRenderer();
    PreviewRenderer(const PreviewRenderer&) = delete;
    PreviewRenderer& operator=(const PreviewRenderer&) = delete;

    const PreviewSettings& settings() const;
    /// Changes settings between frames (the viewer's toggles); GPU resources
    /// follow on the next draw.
    void setSettings(const PreviewSettings& settings);

    /// Renders a frame into the internal target (view.camera's size).
    /// Throws FrameError when GL reports an error.
    void draw(const View& view, const PreviewFrame& frame);
    /// Blocks until the GL has finished the last draw (glFinish), for timing.
    void finish() const;
    /// The last draw as R, G, B, A, Z (top row first).
    Image readback() const;
    /// draw + readback.
    Image render(const View& view, const PreviewFrame& frame);
    /// Draws the last frame, sRGB-encoded, into the bound framebuffer's
    /// viewport (x, y, width, height) — the viewer's window.
    void present(int x, int y, int width, int height) const;
    /// Reads the shadow grid of the last draw of the `slot`-th shadowed light
    /// (empty when voxels were off or there is no such light).
    VoxelSnapshot readVoxels(int slot = 0) const;
    const PreviewStats& stats() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace hp
