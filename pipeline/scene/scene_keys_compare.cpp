// compare.*: the "compare" stage of `hairpipe run` (pipeline/stages/stage_compare.cpp),
// which compares two of the shot's image sequences — by default the preview
// against the reference — with the metrics of render/compare.h.
#include "pipeline/scene/scene_keys.h"

namespace hp {

void addCompareKeys(SchemaBuilder& b) {
    b.section("compare",
              "Compare two rendered sequences frame by frame (FLIP, SSIM, PSNR, RMSE): difference images, "
              "metrics tables and a self-contained HTML report; frames beyond a threshold make the run exit "
              "with code 2. `hairpipe compare A B` does the same for any two sequences.")
        .flag("compare.enabled", false, "Run the compare stage.")
        .text("compare.a", "preview/preview.####.exr",
              "Sequence A (the reference side of FLIP), a frame template relative to the output folder "
              "(or absolute).")
        .text("compare.b", "reference/reference.####.exr",
              "Sequence B (the test side), a frame template relative to the output folder (or absolute).")
        .text("compare.a_label", "",
              "What sequence A is, for the report; empty: named from the scene (\"preview (OpenGL)\", "
              "\"reference (Embree, physical, 8 spp)\", ...) when it is one of the shot's sequences, else its file.")
        .text("compare.b_label", "", "What sequence B is, as compare.a_label.")
        .text("compare.beside", "",
              "A third sequence shown in the report beside A and B, not measured (e.g. the physical reference "
              "when the gate compares against reference.kajiya_kay); a frame template, empty for none.")
        .text("compare.beside_label", "", "What the beside sequence is, as compare.a_label.")
        .text("compare.output", "compare",
              "Folder, relative to the output folder, for flip.####.png (FLIP heat map), absdiff.####.exr "
              "(|A-B|), metrics.####.json and the run's metrics.csv / metrics.json.")
        .text("compare.report", "compare/report.html",
              "The HTML report, relative to the output folder; empty for none. Rewritten at the end of each run.")
        .choice("compare.mask", "hair", {"hair", "none"},
                "hair: average the metrics over pixels whose alpha is > 0 in A or B; none: the whole frame.")
        .number("compare.pixels_per_degree", 67, 1, 1000, "px/deg",
                "FLIP's viewing condition; 67 is a 0.7 m wide 4K display seen from 0.7 m.")
        .number("compare.max_flip", 1, 0, 1, "", "Fail a frame whose mean FLIP exceeds this (1: no limit).")
        .number("compare.min_psnr", 0, 0, 1000, "dB", "Fail a frame whose PSNR is below this (0: no limit).")
        .number("compare.min_ssim", -1, -1, 1, "", "Fail a frame whose SSIM is below this (-1: no limit).")
        .number("compare.max_rmse", 1, 0, 1, "", "Fail a frame whose RMSE exceeds this (1: no limit).")
        .integer("compare.report_width", 512, 16, 8192, "px", "Width of the images embedded in the report.");
}

}  // namespace hp
