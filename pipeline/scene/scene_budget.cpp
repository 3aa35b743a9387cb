#include "pipeline/scene/scene_budget.h"

#include <initializer_list>
#include <string>

namespace hp {

namespace {

/// The key a budget failure is reported at: the first of `keys` the user
/// wrote (so the message points at their file:line), else the first.
const std::string& blame(const Scene& scene, std::initializer_list<const char*> keys) {
    static thread_local std::string chosen;
    chosen = *keys.begin();
    for (const char* k : keys)
        if (scene.given(k)) {
            chosen = k;
            break;
        }
    return chosen;
}

// Products are formed in double: every factor is range-checked and positive,
// so no overflow, and the comparison needs no exact integers.
void check(const Scene& scene, double value, const char* what, const char* budgetKey,
           std::initializer_list<const char*> keys) {
    const double budget = scene.number(budgetKey);
    if (value <= budget) return;
    scene.fail(blame(scene, keys), cat(what, " would be ", value, ", over the budget of ", budget, " (",
                                       budgetKey, "; raise it only on a machine that can hold this)"));
}

}  // namespace

void checkSceneBudget(const Scene& scene) {
    const bool curly = scene.text("hair.model") == "curly-wet";
    const double vertsPerStrand =
        curly ? double(scene.integer("hair.curly.particles")) : double(scene.integer("hair.guides.segments") + 1);
    const char* vertsKey = curly ? "hair.curly.particles" : "hair.guides.segments";
    const double guides = double(scene.integer("hair.guides.count"));
    const double followers = double(scene.integer("hair.followers.count"));

    check(scene, guides * vertsPerStrand, "simulated guide vertices (hair.guides.count × vertices per strand)",
          "budget.guide_vertices", {"hair.guides.count", vertsKey});
    check(scene, (guides + followers) * vertsPerStrand,
          "strand vertices per frame ((guides + followers) × vertices per strand)", "budget.strand_vertices",
          {"hair.followers.count", "hair.guides.count", vertsKey});

    const double pixels = double(scene.integer("render.camera.width")) * double(scene.integer("render.camera.height"));
    const double refScale = scene.number("reference.scale");
    const double ss = double(scene.integer("preview.supersample"));
    check(scene, pixels * ss * ss, "preview pixels (width × height × preview.supersample²)", "budget.image_pixels",
          {"render.camera.width", "render.camera.height", "preview.supersample"});
    const double refPixels = pixels * refScale * refScale;
    check(scene, refPixels, "reference pixels (width × height × reference.scale²)", "budget.image_pixels",
          {"render.camera.width", "render.camera.height", "reference.scale"});
    check(scene, refPixels * double(scene.integer("reference.samples")),
          "reference camera samples per frame (pixels × reference.samples)", "budget.reference_samples",
          {"reference.samples", "render.camera.width", "render.camera.height", "reference.scale"});
}

}  // namespace hp
