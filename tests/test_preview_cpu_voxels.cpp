// The light grids voxelized on the CPU (render/preview/cpu_voxels.h,
// PreviewShadowSettings::voxelize) against the GPU's light passes, which
// they mirror: the same pieces, fragments and deposits, so the grids agree
// but for llvmpipe's fixed-point snapping and float rounding. The grid is
// integer sums, so its bits do not depend on the thread count. The image:
// well within the compare gate's noise (FLIP 0.01 under the hair mask,
// docs/benchmarks.md) of the GPU path's.
//
// Set HAIRPIPE_TEST_DUMP=<folder> to write the images as EXR there.
#include "gl_support.h"
#include "render_support.h"
#include "test_support.h"

#include "render/compare/compare.h"
#include "render/preview/cpu_voxels.h"
#include "render/preview/preview.h"

#include <tbb/task_arena.h>

#include <cmath>
#include <numeric>

namespace hp {
namespace {

using test::dump;

/// Σ|a - b| and Σ b over the voxels, in grid units.
std::pair<double, double> l1AndMass(const std::vector<float>& a, const std::vector<float>& b) {
    double diff = 0.0, mass = 0.0;
    for (size_t i = 0; i < b.size(); ++i) {
        diff += std::abs(double(a[i]) - double(b[i]));
        mass += double(b[i]);
    }
    return {diff, mass};
}

/// The rig's three lights shadowed (key 128³ from the strands, fill and rim
/// 64³ from the key's pieces), on the synthetic hair on its sphere head.
test::HairOnHead rigScene() {
    test::HairOnHead h = test::hairOnHead(320, 240);
    h.view.lights = threePointRig();
    return h;
}

PreviewSettings gridSettings(VoxelizeOn where) {
    PreviewSettings s;
    s.shadow.resolution = 128;
    s.shadow.otherResolution = 64;
    s.shadow.voxelize = where;
    return s;
}

// Each slot's raw grid (V) from the CPU against the GPU's: total mass within
// 0.1 % and at most 0.5 % of it in other voxels (Σ|ΔV| / ΣV; measured
// 0.02-0.04 %, 0.0-0.02 % in mass). What may differ: llvmpipe snaps line
// ends to 1/256 pixel before its diamond tests, so a fragment whose line
// passes within 1/512 pixel of a diamond's corner or a pixel edge changes
// pixel (about 2/512 of fragments near a strand's few ends, each move
// counting twice), and the weights' float rounding moves a deposit's
// fixed-point rounding by a unit. The sorted hair's other lights also check
// that the GPU's captured pieces no longer overflow their buffer (they lost
// 8 % of this scene's pieces before lightPieceVertexBound counted strand.tesc's
// floor of a piece per 4 segments).
TEST(PreviewCpuVoxels, GridMatchesTheGpuLightPasses) {
    HP_REQUIRE_GL();
    const test::HairOnHead h = rigScene();
    for (HairBlend blend : {HairBlend::Sorted, HairBlend::Weighted}) {
        PreviewSettings gs = gridSettings(VoxelizeOn::Gpu), cs = gridSettings(VoxelizeOn::Cpu);
        gs.blend = cs.blend = blend;
        PreviewRenderer gpu(gs), cpu(cs);
        PreviewFrame frame;
        frame.strands = &h.strands;
        frame.head = &h.head;
        gpu.draw(h.view, frame);
        cpu.draw(h.view, frame);
        ASSERT_EQ(gpu.stats().shadowedLights, 3);
        for (int slot = 0; slot < 3; ++slot) {
            const VoxelSnapshot g = gpu.readVoxels(slot), c = cpu.readVoxels(slot);
            ASSERT_EQ(g.resolution, slot == 0 ? 128 : 64);
            ASSERT_EQ(c.resolution, g.resolution);
            const auto [diff, mass] = l1AndMass(c.raw, g.raw);
            const double cpuMass = std::accumulate(c.raw.begin(), c.raw.end(), 0.0);
            ASSERT_GT(mass, 100.0) << "slot " << slot << ": the hair deposits crossings";
            EXPECT_NEAR(cpuMass / mass, 1.0, 1e-3) << "slot " << slot << " blend " << int(blend);
            EXPECT_LT(diff / mass, 0.005) << "slot " << slot << " blend " << int(blend) << ": sum |CPU - GPU| "
                                         << diff << " of " << mass;
        }
    }
}

// The other voxel modes (binary, trilinear) and Dehlin and Styngberg's
// fragment count, one light, a point light's perspective frustum among
// them: the same agreement.
TEST(PreviewCpuVoxels, OtherModesMatchTheGpu) {
    HP_REQUIRE_GL();
    test::HairOnHead h = test::hairOnHead(320, 240);
    for (int mode = 0; mode < 4; ++mode) {
        PreviewSettings gs = gridSettings(VoxelizeOn::Gpu), cs = gridSettings(VoxelizeOn::Cpu);
        for (PreviewSettings* s : {&gs, &cs}) {
            s->shadow.mode = mode == 0 ? VoxelMode::Binary : VoxelMode::Additive;
            s->shadow.splat = mode == 1 ? VoxelSplat::Trilinear : VoxelSplat::Nearest;
            s->shadow.weight = mode == 2 ? VoxelWeight::Fragments : VoxelWeight::Crossings;
        }
        View v = h.view;
        if (mode == 3) {  // a point light above and to the side, outside the hair's bounds
            v.lights[0].type = LightType::Point;
            v.lights[0].position = Vec3f(0.6f, 0.5f, 0.4f);
        }
        PreviewRenderer gpu(gs), cpu(cs);
        PreviewFrame frame;
        frame.strands = &h.strands;
        gpu.draw(v, frame);
        cpu.draw(v, frame);
        const VoxelSnapshot g = gpu.readVoxels(0), c = cpu.readVoxels(0);
        ASSERT_EQ(g.grid.perspective, mode == 3);
        const auto [diff, mass] = l1AndMass(c.raw, g.raw);
        const double cpuMass = std::accumulate(c.raw.begin(), c.raw.end(), 0.0);
        ASSERT_GT(mass, 10.0) << "mode " << mode;
        EXPECT_NEAR(cpuMass / mass, 1.0, 1e-3) << "mode " << mode;
        EXPECT_LT(diff / mass, 0.005) << "mode " << mode << ": sum |CPU - GPU| " << diff << " of " << mass;
    }
}

// The same grids with one thread and with two, bit for bit, in every voxel
// mode (integer deposits, summed by atomic adds in whatever order).
TEST(PreviewCpuVoxels, SameBitsOnOneAndTwoThreads) {
    test::HairOnHead h = rigScene();
    SyntheticHairSettings hs;
    hs.strands = 40000;  // enough work that TBB's second thread takes part (a 3000-strand grid ends before it wakes)
    h.strands = makeSyntheticHair(hs);
    Eigen::AlignedBox3f bounds;
    for (const Vec3f& p : h.strands.positions) bounds.extend(p);
    const std::vector<ShadowSlot> slots = fitShadowSlots(h.view.lights, 3, bounds);
    ASSERT_EQ(slots.size(), 3u);
    const int resolutions[3] = {96, 64, 48};
    tbb::task_arena single(1), both(2);
    std::vector<uint32_t> warm[kMaxShadowedLights];  // wakes the second thread before the grids compared
    both.execute([&] { voxelizeSlotsOnCpu(&h.strands, slots, resolutions, PreviewSettings{}, 32, true, warm); });
    for (int mode = 0; mode < 3; ++mode) {
        PreviewSettings s;
        s.shadow.mode = mode == 0 ? VoxelMode::Binary : VoxelMode::Additive;
        s.shadow.splat = mode == 2 ? VoxelSplat::Trilinear : VoxelSplat::Nearest;
        std::vector<uint32_t> one[kMaxShadowedLights], two[kMaxShadowedLights];
        single.execute([&] { voxelizeSlotsOnCpu(&h.strands, slots, resolutions, s, 32, true, one); });
        both.execute([&] { voxelizeSlotsOnCpu(&h.strands, slots, resolutions, s, 32, true, two); });
        for (int k = 0; k < 3; ++k) {
            ASSERT_EQ(one[k].size(), size_t(resolutions[k]) * resolutions[k] * resolutions[k]);
            EXPECT_GT(std::accumulate(one[k].begin(), one[k].end(), uint64_t(0)), uint64_t(0));
            EXPECT_TRUE(one[k] == two[k]) << "mode " << mode << ", slot " << k;
        }
    }
}

// The preview with its grids from the CPU against the GPU's light passes:
// FLIP under the hair mask below a tenth of the compare gate's noise (0.01;
// measured 4e-5).
TEST(PreviewCpuVoxels, PixelsWithinTheGateNoise) {
    HP_REQUIRE_GL();
    const test::HairOnHead h = rigScene();
    const Image gpu = test::renderOnce(gridSettings(VoxelizeOn::Gpu), h.view, h.strands, &h.head);
    const Image cpu = test::renderOnce(gridSettings(VoxelizeOn::Cpu), h.view, h.strands, &h.head);
    dump("cpu_voxels.gpu", gpu);
    dump("cpu_voxels.cpu", cpu);
    CompareSettings cs;
    cs.mask = MaskMode::Hair;
    const Comparison m = compareImages(gpu, cpu, cs);
    EXPECT_GT(m.metrics.pixels, 1000);
    EXPECT_LT(m.metrics.flip, 0.001) << "FLIP of the CPU grids' preview against the GPU's";
}

TEST(PreviewCpuVoxels, AutoPicksTheCpuOnSoftwareRenderers) {
    EXPECT_TRUE(voxelizeOnCpu(VoxelizeOn::Auto, "llvmpipe (LLVM 15.0.6, 256 bits)"));
    EXPECT_TRUE(voxelizeOnCpu(VoxelizeOn::Auto, "softpipe"));
    EXPECT_FALSE(voxelizeOnCpu(VoxelizeOn::Auto, "NVIDIA H100/PCIe/SSE2"));
    EXPECT_TRUE(voxelizeOnCpu(VoxelizeOn::Cpu, "NVIDIA H100/PCIe/SSE2"));
    EXPECT_FALSE(voxelizeOnCpu(VoxelizeOn::Gpu, "llvmpipe"));
}

}  // namespace
}  // namespace hp
