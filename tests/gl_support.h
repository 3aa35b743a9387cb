// One headless GL context per test process, shared by the GL test files.
#pragma once

#include "core/errors.h"
#include "render/preview/gl_context.h"
#include "render/preview/preview.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

namespace hp::test {

/// The process's headless OpenGL 4.5 context, created on first use; null
/// (with EGL's reason in `why`) when none can be created at all, so tests
/// skip with that reason instead of failing on a machine without GL.
inline GlContext* glContext(std::string* why) {
    static std::unique_ptr<GlContext> ctx;
    static std::string error;
    static bool tried = false;
    if (!tried) {
        tried = true;
        try {
            ctx = GlContext::createHeadless();
        } catch (const Error& e) {
            error = e.what();
        }
    }
    *why = error;
    return ctx.get();
}

/// One frame of `strands` (and `head`, when given) through a fresh preview
/// renderer with settings `s`; its stats in `*stats` and the second shadowed
/// light's voxel grid in `*slot1` when given.
inline Image renderOnce(const PreviewSettings& s, const View& v, const StrandFrame& strands,
                        const TriangleMesh* head = nullptr, PreviewStats* stats = nullptr,
                        VoxelSnapshot* slot1 = nullptr) {
    PreviewRenderer renderer(s);
    PreviewFrame frame;
    frame.strands = &strands;
    frame.head = head;
    Image img = renderer.render(v, frame);
    if (stats) *stats = renderer.stats();
    if (slot1) *slot1 = renderer.readVoxels(1);
    return img;
}

}  // namespace hp::test

#define HP_REQUIRE_GL()                                                            \
    std::string glWhy;                                                             \
    if (!::hp::test::glContext(&glWhy)) GTEST_SKIP() << "no headless OpenGL 4.5 through EGL: " << glWhy
