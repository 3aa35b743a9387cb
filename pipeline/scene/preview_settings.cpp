#include "pipeline/scene/preview_settings.h"
#include "pipeline/scene/key_fields.h"

namespace hp {

PreviewSettings makePreviewSettings(const Scene& s) {
    PreviewSettings p;
    readKeys(s, p, {
        {"preview.msaa", &PreviewSettings::msaa},
        {"preview.supersample", &PreviewSettings::supersample},
        {"preview.min_pixel_width", &PreviewSettings::minPixelWidth},
        {"preview.blend_depth_scale", &PreviewSettings::blendDepthScale},
        {"preview.head", &PreviewSettings::drawHead},
        {"preview.tessellation.level", &PreviewSettings::tessellationLevel},
        {"preview.tessellation.pixels", &PreviewSettings::tessellationPixels},
    });
    p.shadePerFragment = s.text("preview.shading") == "fragment";
    p.shadeInCompute = s.text("preview.shading") == "compute";
    p.blend = s.text("preview.transparency") == "weighted" ? HairBlend::Weighted : HairBlend::Sorted;
    p.curve = s.text("preview.tessellation.curve") == "b-spline" ? CurveType::BSpline : CurveType::CatmullRom;

    PreviewShadowSettings& sh = p.shadow;
    readKeys(s, sh, {
        {"preview.shadow.max_lights", &PreviewShadowSettings::maxLights},
        {"preview.shadow.voxels", &PreviewShadowSettings::voxels},
        {"preview.shadow.sum", &PreviewShadowSettings::sumAlongLight},
        {"preview.shadow.resolution", &PreviewShadowSettings::resolution},
        {"preview.shadow.other_resolution", &PreviewShadowSettings::otherResolution},
        {"preview.shadow.filter", &PreviewShadowSettings::filter},
        {"preview.shadow.alpha", &PreviewShadowSettings::alpha},
        {"preview.shadow.map", &PreviewShadowSettings::shadowMap},
        {"preview.shadow.map_size", &PreviewShadowSettings::shadowMapSize},
        {"preview.shadow.pcf_radius", &PreviewShadowSettings::pcfRadius},
    });
    sh.mode = s.text("preview.shadow.voxel_mode") == "binary" ? VoxelMode::Binary : VoxelMode::Additive;
    sh.splat = s.text("preview.shadow.splat") == "trilinear" ? VoxelSplat::Trilinear : VoxelSplat::Nearest;
    if (sh.mode == VoxelMode::Binary && sh.splat == VoxelSplat::Trilinear)
        s.fail("preview.shadow.splat",
               "trilinear splatting spreads fractions of a fragment, which only adds up with voxel_mode: additive "
               "(Dehlin and Styngberg 2017 compare nearest/binary, nearest/additive and trilinear/additive)");
    const std::string& voxelize = s.text("preview.shadow.voxelize");
    sh.voxelize = voxelize == "cpu" ? VoxelizeOn::Cpu : voxelize == "gpu" ? VoxelizeOn::Gpu : VoxelizeOn::Auto;
    sh.weight = s.text("preview.shadow.weight") == "fragments" ? VoxelWeight::Fragments : VoxelWeight::Crossings;

    GeneratedHairSettings& g = p.generated;
    readKeys(s, g, {
        {"preview.generated.enabled", &GeneratedHairSettings::enabled},
        {"preview.generated.inner_level", &GeneratedHairSettings::innerLevel},
        {"preview.generated.outer_level", &GeneratedHairSettings::outerLevel},
        {"preview.generated.gravity", &GeneratedHairSettings::gravity},
        {"preview.generated.wind", &GeneratedHairSettings::wind},
        {"preview.generated.gust", &GeneratedHairSettings::gust},
        {"preview.generated.gust_frequency", &GeneratedHairSettings::gustFrequency},
        {"preview.generated.gust_wavelength", &GeneratedHairSettings::gustWavelength},
    });
    for (size_t i = 0; i < s.count("preview.generated.types"); ++i) {
        const std::string k = cat("preview.generated.types[", i, "].");
        HairType t;
        t.color = s.vec3f(k + "color");
        t.segments = int(s.integer(k + "segments"));
        t.segmentLength = float(s.number(k + "segment_length"));
        t.forceWeight = float(s.number(k + "force_weight"));
        t.rootRadius = float(s.number(k + "root_radius"));
        t.tipRadius = float(s.number(k + "tip_radius"));
        g.types.push_back(t);
    }
    for (size_t i = 0; i < s.count("preview.generated.regions"); ++i) {
        const std::string k = cat("preview.generated.regions[", i, "].");
        HairRegion r;
        const std::string& shape = s.text(k + "shape");
        r.shape = shape == "all" ? HairRegion::Shape::All : shape == "mask" ? HairRegion::Shape::Mask
                                                                            : HairRegion::Shape::Cap;
        r.type = int(s.integer(k + "type"));
        if (size_t(r.type) >= g.types.size())
            s.fail(k + "type", cat("names hair type ", r.type, " but preview.generated.types has ", g.types.size()));
        r.axis = s.vec3f(k + "axis");
        if (r.shape == HairRegion::Shape::Cap && r.axis.norm() < 1e-6f) s.fail(k + "axis", "must be non-zero");
        r.angle = float(s.number(k + "angle"));
        g.regions.push_back(r);
    }
    return p;
}

}  // namespace hp
