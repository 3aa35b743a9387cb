// render.*: camera, lights and materials shared by the preview (GL) and the
// reference (Embree), so both render the same shot (see render/view.h).
#include "pipeline/scene/scene_keys.h"
#include "render/view.h"

#include <sstream>

namespace hp {

namespace {

/// render.lights' default: render/view.cpp's threePointRig() as a YAML list,
/// so the rig is written down once.
std::string rigYaml() {
    std::ostringstream out;
    auto vec = [&](const Vec3f& v) { out << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]"; };
    out << "[";
    const std::vector<Light> rig = threePointRig();
    for (size_t i = 0; i < rig.size(); ++i) {
        const Light& l = rig[i];
        out << (i ? ", " : "") << "{type: directional, space: camera, direction: ";
        vec(l.direction);
        out << ", color: ";
        vec(l.color);
        out << ", intensity: " << l.intensity << (l.castsShadows ? "" : ", shadows: false") << "}";
    }
    out << "]";
    return out.str();
}

}  // namespace

void addRenderKeys(SchemaBuilder& b) {
    b.section("render", "The shot's look, shared by the preview and the reference renderer.");
    b.section("render.camera",
              "A perspective camera (right-handed, Y up): placed by hand (mode fixed) or framing the head and its "
              "hair by itself (mode auto, the default when no position is given).")
        .choice("render.camera.mode", "auto", {"auto", "follow", "fixed"},
                "auto: frame the head and the hair's reach (scalp grown by the hair length) over the whole clip "
                "from a three-quarter view, framed anew after a scene cut (simulation.cut_distance / "
                "cut_angle: where the simulation restarts the hair); follow: the same, framed on each frame alone; fixed: position and target. "
                "Without the key, a scene that gives render.camera.position is fixed, any other auto; auto without "
                "a head keeps the fixed camera.")
        .choice("render.camera.hair", "reach", {"reach", "cache"},
                "auto/follow: what bounds the hair. reach: the scalp grown by the hair's length (needs no "
                "simulation, frames loosely: hair could stand straight up); cache: the hair itself, read from the "
                "strand cache of every clip frame (tight; `hairpipe run` then simulates the whole clip before it "
                "renders the first frame, and a run without the cache fails naming the missing file).")
        .vec3("render.camera.position", 0, 0.05, 0.9, "m", "Camera position (mode fixed).")
        .vec3("render.camera.target", 0, 0, 0, "m", "Point the camera looks at (mode fixed).")
        .vec3("render.camera.up", 0, 1, 0, "", "Up direction.")
        .vec3("render.camera.facing", 0, 0, 1, "",
              "auto/follow: the head's front in its rest pose (glTF heads face +Z); the view is turned from it.")
        .number("render.camera.azimuth", 35, -180, 180, "deg",
                "auto/follow: camera turned from the face about the up axis (0 = front, 35 = three-quarter, "
                "positive toward the head's left, +X for a +Z face).")
        .number("render.camera.elevation", 8, -80, 80, "deg", "auto/follow: camera raised above the head's level.")
        .number("render.camera.margin", 0.06, 0, 0.9, "",
                "auto/follow: fraction of the half-frame left empty at each border around the framed bounds.")
        .number("render.camera.fov", 40, 1, 170, "deg", "Vertical field of view.")
        .integer("render.camera.width", 1920, 16, 16384, "px", "Image width.")
        .integer("render.camera.height", 1080, 16, 16384, "px", "Image height.")
        .number("render.camera.near", 0.01, 1e-5, 1e3, "m", "Near clipping distance (preview depth range).")
        .number("render.camera.far", 100, 1e-3, 1e6, "m", "Far clipping distance (preview depth range).");
    b.section("render.lights",
              "Lights, a list of maps. The default is a three-point rig that follows the camera (render/view.cpp "
              "threePointRig): a warm key from the upper left, from the side (intensity 1.6, the shadowed light), a cool "
              "fill from the right (0.25) and a rim light from behind and above (1), the last two unshadowed.")
        .list("render.lights", rigYaml(), 16, "Lights of the shot; the default is the three-point rig.")
        .choice("render.lights[].type", "directional", {"directional", "point"}, "Kind of light.")
        .choice("render.lights[].space", "world", {"world", "camera"},
                "Frame of direction and position: world, or the camera's (x right, y up, z toward the viewer; "
                "positions relative to the camera target), so the light follows the camera.")
        .vec3("render.lights[].direction", -1, -1, -1, "", "Directional: the way the light travels.")
        .vec3("render.lights[].position", 0, 1, 1, "m", "Point: position.")
        .vec3("render.lights[].color", 1, 1, 1, "", "Linear RGB colour.")
        .number("render.lights[].intensity", 3, 0, 1e6, "",
                "Directional: radiance scale; point: intensity (falls off with distance squared).")
        .flag("render.lights[].shadows", true,
              "Hair and head block this light. The preview shadows only preview.shadow.light; give other lights "
              "shadows: false to keep preview and reference the same picture.");
    b.section("render.ocio",
              "The view transform of display images (PNG / JPEG previews and references; EXRs stay linear, "
              "scene-referred). Without a config: built-in views, 'filmic' (Narkowicz's ACES fit, then sRGB; "
              "README.md, \"Display transform\") or 'standard' (sRGB alone).")
        .file("render.ocio.config", "", "OpenColorIO config file. Empty: the built-in views.")
        .text("render.ocio.colorspace", "scene_linear", "OCIO colour space (or role) of the rendered radiance.")
        .text("render.ocio.display", "", "OCIO display; empty: the config's default display.")
        .text("render.ocio.view", "",
              "View: 'filmic' or 'standard' built in (empty = filmic); with a config one of its views "
              "(empty = the display's default).");
    b.number("render.exposure", 0, -20, 20, "stops", "Exposure of display images: linear radiance times 2^stops.");
    b.section("render.background", "Backdrop of display images, composited in linear light under the render "
                                   "(EXRs keep their alpha).")
        .choice("render.background.type", "none", {"none", "color", "gradient"},
                "none (transparent PNGs), a flat colour, or a vertical gradient.")
        .vec3("render.background.color", 0.05, 0.05, 0.05, "", "Linear RGB: the colour, or the gradient's top.")
        .vec3("render.background.bottom", 0.015, 0.015, 0.015, "", "Linear RGB at the gradient's bottom.");
    b.vec3("render.environment", 0, 0, 0, "", "Constant environment radiance (linear RGB); black by default.");
    b.section("render.hair", "Kajiya-Kay hair material (seed 004): diffuse kd·sin(t,l), specular ks·sin(t,h)^shininess.")
        .vec3("render.hair.color", 0.35, 0.22, 0.12, "", "Diffuse albedo (linear RGB); replaced by the melanin fit when render.hair.melanin is set.")
        .number("render.hair.melanin", -1, -1, 50, "",
                "Eumelanin concentration (Chiang 2016: ~0.3 blond, ~1.3 brown, ~8 black); -1 = off. When set it "
                "drives both renderers: the physical reference's absorption and, through Chiang's colour fit "
                "inverted (render/hair_bsdf.h hairColorFromAbsorption), the Kajiya-Kay colour.")
        .number("render.hair.pheomelanin", 0, 0, 50, "", "Pheomelanin concentration (red), with render.hair.melanin.")
        .vec3("render.hair.specular_color", 1, 1, 1, "", "Specular colour (linear RGB).")
        .number("render.hair.kd", 0.6, 0, 10, "", "Diffuse weight.")
        .number("render.hair.ks", 0.3, 0, 10, "", "Specular weight.")
        .number("render.hair.shininess", 80, 1, 10000, "", "Specular exponent.")
        .flag("render.hair.two_lobes", false, "Add a second, shifted-tangent specular lobe (Scheuermann 2004).")
        .number("render.hair.primary_shift", 0, -1, 1, "", "Tangent shift of the first lobe along the normal.")
        .number("render.hair.secondary_shift", -0.1, -1, 1, "", "Tangent shift of the second lobe.")
        .number("render.hair.secondary_ks", 0.15, 0, 10, "", "Weight of the second lobe.")
        .number("render.hair.secondary_shininess", 20, 1, 10000, "", "Exponent of the second lobe.")
        .vec3("render.hair.secondary_color", 0.6, 0.45, 0.3, "", "Colour of the second lobe.")
        .number("render.hair.transmittance", 0.8, 0, 1, "",
                "Fraction of light a shadow ray keeps at each strand it crosses (0 = opaque hair, 1 = hair casts "
                "no shadow): hair self-shadowing in both renderers. The reference traces the crossings (kajiya-kay "
                "mode; physical mode carries light through hair with its BSDF); the preview's voxel grid counts "
                "the expected crossings C (preview.shadow.weight: crossings) and lets exp(-(1 - T) C) through.");
    b.section("render.head", "The opaque head's skin-like material: wrapped diffuse plus a faint sheen "
                             "(render/view.h skinShade).")
        .vec3("render.head.color", 0.6, 0.42, 0.33, "", "Diffuse albedo (linear RGB).")
        .number("render.head.ambient", 0.05, 0, 1, "", "Ambient term.")
        .number("render.head.wrap", 0.2, 0, 1, "",
                "Light wrapping past the terminator, (n·l + w)/(1 + w): skin's soft falloff (0 = Lambert).")
        .number("render.head.specular", 0.04, 0, 1, "", "Weight of the Blinn-Phong sheen.")
        .number("render.head.shininess", 30, 1, 10000, "", "Exponent of the sheen.");
}

}  // namespace hp
