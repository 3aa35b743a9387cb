// limits.*: resource budgets checked across keys before anything is allocated
// (pipeline/scene_budget.h). Each key alone has a range; these bound products
// of keys (strand count × vertices, image size × samples) that could ask for
// more memory or time than any machine has. Raise them on a bigger machine.
#include "pipeline/scene_keys.h"

namespace hp {

void addLimitKeys(SchemaBuilder& b) {
    b.section("limits",
              "Budgets across keys, checked when the scene is loaded so that an absurd combination fails with a "
              "message instead of exhausting memory. The defaults fit a 24 GiB workstation.")
        .integer("limits.strand_vertices", 50000000, 1, 2147483647, "",
                 "Most strand vertices in a frame: (hair.guides.count + hair.followers.count) × vertices per "
                 "strand (hair.guides.segments + 1, or hair.curly.particles). About 150 bytes each through "
                 "simulation and rendering.")
        .integer("limits.guide_vertices", 5000000, 1, 2147483647, "",
                 "Most simulated guide vertices: hair.guides.count × vertices per strand (each one is a Bullet "
                 "soft-body node).")
        .integer("limits.image_pixels", 268435456, 1, 2147483647, "px",
                 "Most pixels of a rendered image: render.camera.width × height, times reference.scale² for the "
                 "reference and preview.supersample² for the preview (default 16384²).")
        .number("limits.reference_samples", 1e10, 1, 1e15, "",
                "Most camera samples of one reference frame: pixels × reference.samples (default: about 4K at "
                "1200 samples per pixel).")
        .number("limits.collider_voxels", 2e8, 1, 1e12, "",
                "Most voxels of the head's signed distance grid: about the head's area × (exterior + interior "
                "band) / voxel_size³ (head.collider.*).");
}

}  // namespace hp
