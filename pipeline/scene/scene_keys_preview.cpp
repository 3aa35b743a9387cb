// preview.*: the real-time GL preview pass (seed 004; render/preview.h).
#include "pipeline/scene/scene_keys.h"

namespace hp {

void addPreviewKeys(SchemaBuilder& b) {
    b.section("preview",
              "The real-time OpenGL preview (seed 004): strands smoothed by tessellation and drawn as "
              "camera-facing ribbons, generated fur, Kajiya-Kay shading (render.hair), voxel self-shadows "
              "and a shadow map of the head. Headless through EGL (llvmpipe without a GPU).")
        .flag("preview.enabled", false, "Render preview frames in `hairpipe run` (`render --preview` always does).")
        .text("preview.exr", "preview/preview.####.exr",
              "EXR frame template, relative to the output folder: half R, G, B, A (premultiplied, "
              "linear) and float Z (camera depth in metres, +inf where empty). Empty: none.")
        .text("preview.png", "preview/preview.####.png",
              "PNG frame template (sRGB 8-bit with alpha). Empty: none.")
        .integer("preview.msaa", 4, 1, 16, "samples", "Multisample antialiasing (clamped to what the driver offers).")
        .integer("preview.supersample", 1, 1, 4, "",
                 "Render at N x N the resolution and average (on top of MSAA); costs N^2.")
        .choice("preview.shading", "vertex", {"vertex", "fragment"},
                "Where hair is shaded: at the tessellated strand points (fast, Gouraud along the strand) or "
                "per fragment (sharper highlights and shadow edges, several times slower on llvmpipe).")
        .number("preview.min_pixel_width", 1, 0.05, 16, "px",
                "Thinnest ribbon drawn; thinner hair is drawn this wide with alpha = true width / drawn "
                "width, so its coverage stays right instead of aliasing away.")
        .choice("preview.transparency", "sorted", {"sorted", "weighted"},
                "How semi-transparent hair is composited. sorted: strands cut into 4-segment pieces sorted back "
                "to front every frame and blended with the over operator, what the reference's rays see. "
                "weighted: unsorted weighted blended order-independent transparency (McGuire & Bavoil 2013), "
                "cheaper, but hair deep in the volume tints the front.")
        .number("preview.blend_depth_scale", 0.02, 1e-4, 10, "m",
                "transparency: weighted only: blending weights colour by exp(-depth behind the scene's front / "
                "this); smaller lets the nearest hair dominate more.")
        .flag("preview.head", true, "Draw the head mesh (Lambert + ambient, render.head).");
    b.section("preview.tessellation", "Smoothing of strand polylines by isoline tessellation.")
        .choice("preview.tessellation.curve", "catmull-rom", {"catmull-rom", "b-spline"},
                "Curve through the strand's vertices (Catmull-Rom) or approximating them (uniform B-spline).")
        .integer("preview.tessellation.level", 8, 1, 64, "", "Most pieces per strand segment.")
        .number("preview.tessellation.pixels", 20, 0, 1000, "px",
                "Target on-screen length of a piece: each strand's curve is cut into about its screen length / "
                "this pieces (at most `level` per segment). 20 px keeps chords within ~0.25 px of curves of "
                "radius > 200 px; smaller is smoother and slower (llvmpipe pays per piece). 0 = always `level`.");
    b.section("preview.shadow",
              "Shadows of one light (seed 004, 2.3): hair voxelized from the light into a 3D texture and "
              "summed along the light (transmittance alpha^C), times a PCF shadow map of the head. "
              "Point lights use a perspective frustum; other lights are unshadowed.")
        .integer("preview.shadow.light", 0, -1, 15, "", "Index into render.lights of the shadowed light; -1 = none.")
        .flag("preview.shadow.voxels", true, "Hair self-shadowing through the voxel grid.")
        .choice("preview.shadow.voxel_mode", "additive", {"binary", "additive"},
                "Per strand fragment: set its voxel to 1 (occupancy) or add 1 (density).")
        .choice("preview.shadow.splat", "nearest", {"nearest", "trilinear"},
                "Update the fragment's voxel, or the 8 around it with trilinear weights (additive only).")
        .flag("preview.shadow.sum", true,
              "Sum the grid along the light (the seed's C). Off shades with the raw voxel values, the seed's "
              "figures of the voxelization itself.")
        .integer("preview.shadow.resolution", 256, 8, 1024, "voxels", "Voxels along each axis of the light's box.")
        .flag("preview.shadow.filter", true,
              "Average C over 2 x 2 voxels across the light when shading (hides the moire rings regularly spaced "
              "hair casts); off = the seed's single lookup.")
        .choice("preview.shadow.weight", "crossings", {"crossings", "fragments"},
                "What the grid counts. crossings: each strand fragment adds the strand crossings a light ray "
                "through its voxel column expects (its projected area there), so C counts crossings and light "
                "reaching a point is exp(-(1 - T) C) with T = render.hair.transmittance, the reference's "
                "per-crossing transmittance (binary: an occupied voxel counts as one crossing of its widest "
                "strand). fragments: the seed's count, 1 per fragment whatever the hair's width, light = alpha^C.")
        .number("preview.shadow.alpha", 0.85, 0.001, 1, "",
                "weight: fragments only: transmittance per unit of C (strand fragments with voxel_mode additive, "
                "occupied voxels with binary).")
        .flag("preview.shadow.map", true, "Shadow map of the opaque head.")
        .integer("preview.shadow.map_size", 2048, 64, 16384, "px", "Shadow map resolution.")
        .integer("preview.shadow.pcf_radius", 1, 0, 8, "texels", "Percentage-closer filter: (2r+1)^2 taps.");
    b.section("preview.generated",
              "Generated hair (seed 004): short hair and fur grown on the GPU from the head mesh, one strand per "
              "PN-tessellated triangle, bent toward gravity + wind; needs a head.")
        .flag("preview.generated.enabled", false, "Grow generated hair on the regions below.")
        .integer("preview.generated.inner_level", 4, 1, 64, "", "Inner tessellation level of region triangles.")
        .integer("preview.generated.outer_level", 4, 1, 64, "", "Outer tessellation level of region triangles.")
        .vec3("preview.generated.gravity", 0, -0.2, 0, "",
              "Added to the unit growth direction at each segment (times the type's force weight).")
        .vec3("preview.generated.wind", 0.1, 0, 0, "", "Wind force, same units; gusts travel along it.")
        .number("preview.generated.gust", 0.5, 0, 10, "", "Gust strength relative to the wind.")
        .number("preview.generated.gust_frequency", 0.5, 0, 100, "Hz", "Gusts per second.")
        .number("preview.generated.gust_wavelength", 0.25, 1e-3, 100, "m", "Distance between gust fronts.")
        .list("preview.generated.types", "[{}]", 16, "Hair types (the seed's hair-type texture), 0-based.")
        .vec3("preview.generated.types[].color", 0.85, 0.8, 0.7, "", "Albedo (linear RGB).")
        .integer("preview.generated.types[].segments", 4, 1, 16, "", "Segments per strand; fewer = stiffer.")
        .number("preview.generated.types[].segment_length", 0.004, 1e-5, 1, "m", "Length of one segment.")
        .number("preview.generated.types[].force_weight", 1, 0, 100, "", "Scales the force per segment.")
        .number("preview.generated.types[].root_radius", 0.00004, 1e-7, 0.01, "m", "Radius at the root.")
        .number("preview.generated.types[].tip_radius", 0.00001, 1e-7, 0.01, "m", "Radius at the tip.")
        .list("preview.generated.regions", "[{}]", 32,
              "Where each type grows; later regions override earlier ones on shared triangles.")
        .choice("preview.generated.regions[].shape", "cap", {"all", "cap", "mask"},
                "Every triangle, a spherical cap around `axis` from the head's centre (head's rest frame), or "
                "the head's scalp mask from head import.")
        .integer("preview.generated.regions[].type", 0, 0, 15, "", "Index into preview.generated.types.")
        .vec3("preview.generated.regions[].axis", 0, 1, 0, "", "Cap: its centre direction.")
        .number("preview.generated.regions[].angle", 60, 0, 180, "deg", "Cap: half-angle.");
}

}  // namespace hp
