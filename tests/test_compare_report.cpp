// What the compare stage reports: the pass/fail tables (pipeline/compare/compare_table.h)
// and the labels of the report's sides, taken from the scene
// (pipeline/compare/compare_job.h, pipeline/compare/compare_report.h). The metrics, files and
// command line are in test_compare.cpp.
#include "core/errors.h"
#include "pipeline/compare/compare_job.h"
#include "pipeline/compare/compare_report.h"
#include "pipeline/compare/compare_table.h"
#include "pipeline/scene/scene.h"

#include <gtest/gtest.h>

namespace hp {

TEST(CompareFiles, ThresholdsAndTables) {
    FrameMetrics m;
    m.flip = 0.3, m.ssim = 0.7, m.psnr = 20, m.rmse = 0.1;
    EXPECT_TRUE(checkThresholds(m, {}).empty()) << "the defaults are no limits";
    const auto f = checkThresholds(m, {0.25, 30, 0.8, 0.05});
    ASSERT_EQ(f.size(), 4u);
    EXPECT_EQ(f[0], "FLIP 0.3 > 0.25");
    EXPECT_EQ(f[1], "PSNR 20 dB < 30 dB");
    FrameRecord ok, bad;
    ok.frame = 1, ok.compared = true, ok.metrics = m;
    bad.frame = 2, bad.error = "b.0002.exr: no such file", bad.a = "a,0002.exr";
    const std::string csv = metricsCsv({ok, bad});
    EXPECT_NE(csv.find("\n1,,,pass,0,0.1,20,0,0.7,0.3,\n"), std::string::npos) << csv;
    EXPECT_NE(csv.find("\n2,\"a,0002.exr\",,error,,,,,,,b.0002.exr: no such file\n"), std::string::npos) << csv;
    const CompareSummary s = summarize({ok, bad});
    EXPECT_EQ(s.compared, 1);
    EXPECT_EQ(s.failed, 1);
    EXPECT_FALSE(s.pass());
}

TEST(CompareReport, SidesAreLabelledFromTheScene) {
    const Scene scene = Scene::parse("reference: {mode: physical, samples: 8, kajiya_kay: {enabled: true, samples: 4}}\n"
                                     "compare: {b: reference/kajiya-kay.####.exr, beside: reference/reference.####.exr}\n",
                                     "labels.yaml", ".");
    const CompareJob job = compareJobFromScene(scene, "/tmp/shot");
    EXPECT_EQ(job.aLabel, "preview (OpenGL)");
    EXPECT_EQ(job.bLabel, "reference (Embree, kajiya-kay, 4 spp)");  // its own budget
    EXPECT_EQ(job.beside, "/tmp/shot/reference/reference.####.exr");
    EXPECT_EQ(job.besideLabel, "reference (Embree, physical, 8 spp)");
    const std::string html = compareReportHtml(job, {});
    EXPECT_NE(html.find("A: preview (OpenGL)"), std::string::npos);
    EXPECT_NE(html.find("beside: reference (Embree, physical, 8 spp)"), std::string::npos);
    EXPECT_NE(html.find("measured pair"), std::string::npos);
    EXPECT_EQ(html.find("A (reference)"), std::string::npos);
    EXPECT_EQ(html.find("B (test)"), std::string::npos);
    // A label the scene gives wins; an unknown sequence is named by its template.
    const CompareJob other = compareJobFromScene(
        Scene::parse("compare: {a: other/x.####.exr, b_label: my render}\n", "labels.yaml", "."), "/tmp/shot");
    EXPECT_EQ(other.aLabel, "other/x.####.exr");
    EXPECT_EQ(other.bLabel, "my render");
    try {
        compareJobFromScene(Scene::parse("compare: {beside: still.exr}\n", "labels.yaml", "."), "/tmp/shot");
        FAIL() << "a beside template without a frame number must be refused";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("compare.beside"), std::string::npos) << e.what();
    }
}

// The gate pair and the diagnostic pair say which pair they are, in the
// report and metrics.json; the diagnostic writes beside the gate, never
// over it, and has no thresholds.
TEST(CompareReport, GateAndDiagnosticPairsAreNamed) {
    const Scene scene = Scene::parse("reference: {mode: physical, samples: 8, kajiya_kay: {enabled: true, samples: 4}}\n"
                                     "compare: {diagnostic: reference/kajiya-kay.####.exr, max_flip: 0.5}\n",
                                     "pairs.yaml", ".");
    const CompareJob gate = compareJobFromScene(scene, "/tmp/shot");
    EXPECT_EQ(gate.bLabel, "reference (Embree, physical, 8 spp)");
    EXPECT_NE(gate.pair.find("gate"), std::string::npos) << gate.pair;
    const std::optional<CompareJob> diag = diagnosticJobFromScene(scene, "/tmp/shot");
    ASSERT_TRUE(diag);
    EXPECT_EQ(diag->b, "/tmp/shot/reference/kajiya-kay.####.exr");
    EXPECT_EQ(diag->bLabel, "reference (Embree, kajiya-kay, 4 spp)");
    EXPECT_NE(diag->pair.find("same model, other visibility"), std::string::npos) << diag->pair;
    EXPECT_EQ(diag->outputDir, gate.outputDir / "diagnostic");
    EXPECT_NE(diag->report, gate.report);
    EXPECT_EQ(diag->thresholds.maxFlip, 1.0);
    EXPECT_NE(compareReportHtml(*diag, {}).find("same model, other visibility"), std::string::npos);
    EXPECT_NE(metricsJson(*diag, {}).find("\"pair\": \"diagnostic, same model, other visibility"), std::string::npos);
    EXPECT_NE(compareReportHtml(gate, {}).find(gate.pair), std::string::npos);
    // None without the key; the gate's own sequence is refused.
    EXPECT_FALSE(diagnosticJobFromScene(Scene::parse("", "pairs.yaml", "."), "/tmp/shot"));
    EXPECT_THROW(diagnosticJobFromScene(Scene::parse("compare: {diagnostic: reference/reference.####.exr}\n",
                                                     "pairs.yaml", "."),
                                        "/tmp/shot"),
                 SceneError);
}

}  // namespace hp
