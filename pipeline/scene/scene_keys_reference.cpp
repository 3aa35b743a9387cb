// reference.*: the Embree reference renderer (render/reference.h), mapped
// onto ReferenceSettings by pipeline/stages/stage_reference.cpp.
#include "pipeline/scene/scene_keys.h"

namespace hp {

void addReferenceKeys(SchemaBuilder& b) {
    b.section("reference",
              "Ray-traced reference frames (Embree) of the hair and head, to compare the preview against. "
              "Camera, lights and the Kajiya-Kay material come from render.*; `hairpipe render --reference` "
              "runs only this stage.")
        .flag("reference.enabled", false, "Render reference frames.")
        .text("reference.exr", "reference/reference.####.exr",
              "EXR output template, relative to the output directory: R, G, B, A (half, linear, premultiplied), "
              "Z (float view-space depth; render.camera.far where nothing was hit) and the layers asked for.")
        .text("reference.png", "reference/reference.####.png",
              "PNG output template (sRGB 8-bit RGBA) for quick viewing; empty writes no PNG.")
        .choice("reference.mode", "kajiya-kay", {"kajiya-kay", "physical"},
                "Shading: `kajiya-kay` is the preview's model (render.hair.*) with direct light and ray-traced "
                "shadows; `physical` path-traces Chiang et al. 2016's hair BSDF (reference.physical.*) and a "
                "Lambertian head (reference.kajiya_kay adds the Kajiya-Kay one beside it).")
        .integer("reference.samples", 16, 1, 4096, "", "Samples per pixel (stratified over the pixel, box filter).")
        .integer("reference.depth", 4, 0, 64, "",
                 "Physical mode: indirect bounces after the first hit, as Cycles' max bounces (0 = direct light "
                 "only).")
        .flag("reference.shadows", true, "Trace shadow rays toward each light.")
        .number("reference.shadow_roulette", 0.03125, 0, 10, "1/sr",
                "Physical mode: a light sample whose unshadowed contribution (path throughput x BSDF, max over "
                "RGB) is below this traces its shadow ray only with probability contribution/threshold, weighted "
                "by the inverse: unbiased and much faster for dark hair, slightly noisier; 0 traces every shadow "
                "ray.")
        .number("reference.scale", 1, 0.01, 4, "",
                "Image size relative to render.camera.width and height (e.g. 0.25 for a quick look).");
    b.section("reference.kajiya_kay",
              "Physical mode: a second reference of the same frames shaded with the preview's Kajiya-Kay model "
              "(same camera, lights, samples and seed), so compare can gate the preview against a reference that "
              "differs from it only in visibility, shadows and anti-aliasing, not in the hair's BSDF.")
        .flag("reference.kajiya_kay.enabled", false, "Render the Kajiya-Kay reference too (about doubles the stage's time).")
        .text("reference.kajiya_kay.exr", "reference/kajiya-kay.####.exr", "Its EXR template (channels as reference.exr).")
        .text("reference.kajiya_kay.png", "reference/kajiya-kay.####.png", "Its PNG template; empty writes none.");
    b.section("reference.layers", "Extra EXR layers.")
        .flag("reference.layers.diffuse_specular", false,
              "Add diffuse.R/G/B and specular.R/G/B (Kajiya-Kay: its two terms; physical: the R lobe of direct "
              "light at the first hit, and the rest).")
        .flag("reference.layers.strand_id", false,
              "Add strand_id: the stable id of the strand nearest to the camera in each pixel, -1 for none.");
    b.section("reference.physical", "Physical mode hair fibre (Chiang et al. 2016).")
        .number("reference.physical.melanin", 1.3, 0, 50, "",
                "Eumelanin concentration: ~0.3 blond, ~1.3 brown, ~8 black.")
        .number("reference.physical.pheomelanin", 0, 0, 50, "", "Pheomelanin concentration (adds red).")
        .flag("reference.physical.use_hair_color", false,
              "Derive the absorption from render.hair.color (the paper's colour inversion) instead of melanin, "
              "to match the Kajiya-Kay colour.")
        .number("reference.physical.roughness", 0.3, 0.01, 1, "", "Longitudinal roughness beta_m.")
        .number("reference.physical.azimuthal_roughness", 0.3, 0.01, 1, "", "Azimuthal roughness beta_n.")
        .number("reference.physical.cuticle_tilt", 2, -10, 10, "deg", "Cuticle scale tilt alpha.")
        .number("reference.physical.ior", 1.55, 1.01, 3, "", "Index of refraction of the fibre.");
}

}  // namespace hp
