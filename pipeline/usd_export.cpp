#include "pipeline/usd_export.h"

#include "core/errors.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

namespace hp {

namespace {

using File = std::unique_ptr<FILE, int (*)(FILE*)>;

void vec3Array(FILE* f, const std::vector<Vec3f>& v) {
    std::fputc('[', f);
    for (size_t i = 0; i < v.size(); ++i)
        std::fprintf(f, "%s(%.9g, %.9g, %.9g)", i ? ", " : "", v[i].x(), v[i].y(), v[i].z());
    std::fputc(']', f);
}

template <typename T>
void scalarArray(FILE* f, const std::vector<T>& v, const char* format, double scale = 1.0) {
    std::fputc('[', f);
    for (size_t i = 0; i < v.size(); ++i) {
        if (i) std::fputs(", ", f);
        std::fprintf(f, format, double(v[i]) * scale);
    }
    std::fputc(']', f);
}

}  // namespace

void writeUsdCurves(const std::filesystem::path& path, const std::vector<const StrandFrame*>& frames,
                    const UsdExportSettings& s) {
    if (frames.empty()) throw Error("USD export: no frames");
    const StrandFrame& first = *frames.front();
    for (const StrandFrame* fr : frames) {
        fr->validate();
        if (fr->offsets != first.offsets)
            throw Error(cat("USD export: frame ", fr->frame, " has different strands than frame ", first.frame));
    }
    File f(std::fopen(path.c_str(), "w"), &std::fclose);
    if (!f) throw IoError(path.string(), std::strerror(errno));
    FILE* out = f.get();
    std::fprintf(out,
                 "#usda 1.0\n(\n    defaultPrim = \"%s\"\n    metersPerUnit = 1\n    upAxis = \"Y\"\n"
                 "    timeCodesPerSecond = %g\n    startTimeCode = %d\n    endTimeCode = %d\n"
                 "    doc = \"hairpipe strands\"\n)\n\n",
                 s.primPath.substr(1).c_str(), s.fps, first.frame, frames.back()->frame);
    std::fprintf(out, "def BasisCurves \"%s\" (\n    kind = \"component\"\n)\n{\n", s.primPath.substr(1).c_str());
    std::fputs("    uniform token type = \"linear\"\n    uniform token wrap = \"nonperiodic\"\n", out);
    std::vector<int> counts(first.strandCount());
    for (size_t i = 0; i < counts.size(); ++i) counts[i] = int(first.vertexCount(i));
    std::fputs("    int[] curveVertexCounts = ", out);
    scalarArray(out, counts, "%.0f");
    std::fputs("\n    point3f[] points.timeSamples = {\n", out);
    for (const StrandFrame* fr : frames) {
        std::fprintf(out, "        %d: ", fr->frame);
        vec3Array(out, fr->positions);
        std::fputs(",\n", out);
    }
    std::fputs("    }\n", out);
    if (!first.velocities.empty()) {
        std::fputs("    vector3f[] velocities.timeSamples = {\n", out);
        for (const StrandFrame* fr : frames) {
            std::fprintf(out, "        %d: ", fr->frame);
            vec3Array(out, fr->velocities);
            std::fputs(",\n", out);
        }
        std::fputs("    }\n", out);
    }
    std::fputs("    float[] widths.timeSamples = {\n", out);
    for (const StrandFrame* fr : frames) {
        std::fprintf(out, "        %d: ", fr->frame);
        scalarArray(out, fr->radii, "%.9g", 2.0);
        std::fputs(",\n", out);
    }
    std::fputs("    }\n    uniform token widths:interpolation = \"vertex\"\n", out);
    std::fputs("    int[] primvars:hairpipe:strandId = ", out);
    scalarArray(out, first.ids, "%.0f");
    std::fputs("\n    uniform token primvars:hairpipe:strandId:interpolation = \"uniform\"\n", out);
    std::fprintf(out, "    int primvars:hairpipe:guideCount = %u\n}\n", first.guideCount);
    if (std::ferror(out) || std::fflush(out) != 0) throw IoError(path.string(), "write failed (disk full?)");
}

void writeUsdCurves(const std::filesystem::path& path, const StrandFrame& frame, const UsdExportSettings& s) {
    writeUsdCurves(path, std::vector<const StrandFrame*>{&frame}, s);
}

}  // namespace hp
