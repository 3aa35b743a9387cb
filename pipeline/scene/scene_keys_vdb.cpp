// vdb.*: the OpenVDB density cache (pipeline/stages/stage_vdb.cpp, render/voxelizer.h,
// render/vdb_writer.h).
#include "pipeline/scene/scene_keys.h"

namespace hp {

void addVdbKeys(SchemaBuilder& b) {
    b.section("vdb",
              "OpenVDB density caches: the hair voxelized per frame into one file holding a fog-volume "
              "FloatGrid named `density` (hair volume fraction: m³ of hair per m³, so Σ density × voxel "
              "volume = hair volume) and optionally a `velocity` grid. Load them in Blender (Add > Volume > "
              "Import OpenVDB), Houdini (File SOP) or inspect with vdb_print.")
        .flag("vdb.enabled", false, "Write a VDB file per frame (the `vdb` stage of `hairpipe run`).")
        .number("vdb.voxel_size", 0.001, 1e-5, 1.0, "m",
                "Edge of the cubic voxels (world-aligned, voxel centres at multiples of it). Halving it "
                "multiplies file size and time by about 4-8.")
        .text("vdb.output", "vdb/hair.####.vdb",
              "File template relative to the output directory; one `#` per digit of the frame number "
              "(or %04d).")
        .choice("vdb.filter", "trilinear", {"trilinear", "box"},
                "How each segment's volume is spread: `trilinear` over the 8 voxels around each point "
                "(smooth, no flicker as strands cross voxels, 2 voxels wide) or `box` into the voxel "
                "containing it (sharp, 1 voxel wide, fewer active voxels). Both conserve hair volume.")
        .flag("vdb.velocity", false,
              "Also write a `velocity` grid (vec3, m/s): the density-weighted mean velocity of the hair "
              "in each voxel, for motion blur.")
        .choice("vdb.compression", "blosc", {"blosc", "none"},
                "File compression: Blosc (OpenVDB's default, read by Blender and Houdini) or none "
                "(larger files, faster to write).")
        .flag("vdb.half_float", false,
              "Store values as 16-bit floats: half the file size, about 3 significant digits.")
        .number("vdb.density_scale", 1.0, 1e-9, 1e9, "",
                "Factor applied to the written density (e.g. an extinction scale, so renderers need "
                "no density multiplier); written as metadata `density_scale`.")
        .number("vdb.max_memory", 8.0, 0.01, 1024.0, "GiB",
                "A frame whose grid would need more memory than this fails with a message instead of "
                "exhausting the machine (a voxel size far too small).");
}

}  // namespace hp
