// budget.*: resource budgets checked across keys when a scene is loaded
// (pipeline/scene/scene_budget.h). Each key alone has a range; these bound products
// of keys (strand count × vertices, image size × samples) that could ask for
// more memory or time than any machine has. Raise them on a bigger machine.
#include "pipeline/scene/scene_keys.h"

namespace hp {

void addBudgetKeys(SchemaBuilder& b) {
    b.section("budget",
              "Budgets across keys, checked when the scene is loaded so that an absurd combination fails with a "
              "message naming the keys instead of exhausting memory hours later. The defaults fit a 24 GiB "
              "workstation.")
        .number("budget.strand_vertices", 5e7, 1, 1e12, "",
                 "Most strand vertices in a frame: (hair.guides.count + hair.followers.count) × vertices per "
                 "strand (hair.guides.segments + 1, or hair.curly.particles for the curly-wet model). About "
                 "150 bytes each through simulation and rendering.")
        .number("budget.guide_vertices", 5e6, 1, 1e12, "",
                 "Most simulated guide vertices: hair.guides.count × vertices per strand (each one is a "
                 "soft-body node or particle).")
        .number("budget.image_pixels", 268435456, 1, 1e12, "px",
                 "Most pixels of a rendered image: render.camera.width × height, times reference.scale² for the "
                 "reference and preview.supersample² for the preview (default 16384²).")
        .number("budget.reference_samples", 1e10, 1, 1e15, "",
                "Most camera samples of one reference frame: its pixels × reference.samples (default: about "
                "4K at 1200 samples per pixel).");
}

}  // namespace hp
