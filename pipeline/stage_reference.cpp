// The "reference" frame stage: renders each frame's strands and head with the
// Embree reference renderer (render/reference.h) and writes EXR (+ PNG).
#include "core/log.h"
#include "pipeline/output.h"
#include "pipeline/path_template.h"
#include "pipeline/stages.h"
#include "pipeline/view_settings.h"
#include "render/reference.h"

#include <algorithm>
#include <cmath>

namespace fs = std::filesystem;

namespace hp {

namespace {

ReferenceSettings referenceSettings(const Scene& s, const ShotSettings& shot) {
    ReferenceSettings r;
    r.mode = s.text("reference.mode") == "physical" ? ReferenceMode::Physical : ReferenceMode::KajiyaKay;
    r.samplesPerPixel = int(s.integer("reference.samples"));
    r.bounces = int(s.integer("reference.depth"));
    r.seed = uint64_t(shot.seed);
    r.shadows = s.flag("reference.shadows");
    r.shadowRouletteThreshold = float(s.number("reference.shadow_roulette"));
    r.diffuseSpecularLayers = s.flag("reference.layers.diffuse_specular");
    r.strandIdLayer = s.flag("reference.layers.strand_id");
    HairFiberParams& f = r.fiber;
    f.longitudinalRoughness = float(s.number("reference.physical.roughness"));
    f.azimuthalRoughness = float(s.number("reference.physical.azimuthal_roughness"));
    f.cuticleTiltDegrees = float(s.number("reference.physical.cuticle_tilt"));
    f.ior = float(s.number("reference.physical.ior"));
    f.sigmaA = hairAbsorption(s);
    return r;
}

std::string checkedTemplate(const Scene& s, const std::string& key, bool required) {
    const std::string& t = s.text(key);
    if (t.empty()) {
        if (required) s.fail(key, "must name the output file template");
        return t;
    }
    if (!hasFrameToken(t)) s.fail(key, "needs a frame token (#### or %04d) so frames do not overwrite each other");
    return t;
}

class ReferenceStage final : public FrameStage {
  public:
    ReferenceStage(const Scene& scene, const ShotSettings& shot)
        : shot_(shot), view_(makeView(scene)), display_(makeDisplaySettings(scene)),
          settings_(referenceSettings(scene, shot)),
          exr_(checkedTemplate(scene, "reference.exr", true)), png_(checkedTemplate(scene, "reference.png", false)),
          sceneName_(scene.name()) {
        const double scale = scene.number("reference.scale");
        view_.camera.width = std::max(1, int(std::lround(view_.camera.width * scale)));
        view_.camera.height = std::max(1, int(std::lround(view_.camera.height * scale)));
    }

    std::string name() const override { return "reference"; }

    std::vector<fs::path> outputs(int frame) const override {
        std::vector<fs::path> out{shot_.outputDir / expandFrame(exr_, frame)};
        if (!png_.empty()) out.push_back(shot_.outputDir / expandFrame(png_, frame));
        return out;
    }

    void run(const FrameData& data) override {
        const TriangleMesh* head = data.head && !data.head->mesh.triangles.empty() ? &data.head->mesh : nullptr;
        if (!data.strands && !head)
            throw FrameError(cat("frame ", data.frame,
                                 " has neither strands nor a head to render (no hair or head stage produced them)"));
        if (!data.strands) logVerbose("reference: frame ", data.frame, " has no strands; rendering the head alone");

        ReferenceSettings settings = settings_;
        settings.frame = data.frame;
        int lastDecile = 0;
        settings.progress = [&](size_t done, size_t total) {
            const int decile = int(10 * done / total);
            if (decile > lastDecile) {
                lastDecile = decile;
                logVerbose("reference: frame ", data.frame, " ", 10 * decile, "%");
            }
        };
        ReferenceStats stats;
        const Image image = renderer_.render(view_, data.strands, head, settings, &stats);
        logVerbose("reference: frame ", data.frame, ": ", stats.strands, " strands, ", settings.samplesPerPixel,
                   " spp, ", referenceModeName(settings.mode), ", build ", stats.buildSeconds, " s, render ",
                   stats.renderSeconds, " s, Embree ", stats.sceneBytes / (1 << 20), " MiB");

        ImageWriteOptions options;
        options.metadata = {{"hairpipe:stage", "reference"},
                            {"hairpipe:scene", sceneName_},
                            {"hairpipe:frame", std::to_string(data.frame)},
                            {"hairpipe:seed", std::to_string(shot_.seed)},
                            {"hairpipe:mode", referenceModeName(settings.mode)},
                            {"hairpipe:samples", std::to_string(settings.samplesPerPixel)},
                            {"hairpipe:strands", std::to_string(stats.strands)}};
        const std::vector<fs::path> paths = outputs(data.frame);
        for (const fs::path& path : paths)
            writeAtomically(path, [&](const fs::path& tmp) { writeImageWithDisplay(tmp.string(), image, display_, options); });
    }

  private:
    ShotSettings shot_;
    View view_;
    DisplaySettings display_;  // PNG frames only; EXRs stay linear
    ReferenceSettings settings_;
    std::string exr_, png_;
    std::string sceneName_;
    ReferenceRenderer renderer_;  // one Embree device for the whole shot
};

}  // namespace

StagePtr makeReferenceStage(const Scene& scene, const ShotSettings& shot) {
    if (!scene.flag("reference.enabled")) return nullptr;
    return std::make_unique<ReferenceStage>(scene, shot);
}

}  // namespace hp
