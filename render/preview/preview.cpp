// The preview's passes per frame: upload, shadow map, voxelization + sum
// along the light, the camera pass (opaque head, then hair with weighted
// blended transparency), and the resolve. See render/preview/preview.h.
#include "render/preview/preview.h"

#include "core/errors.h"
#include "core/log.h"
#include "render/preview/cpu_voxels.h"
#include "render/preview/gl_program.h"
#include "render/preview/line_pieces.h"
#include "render/preview/pass_clock.h"
#include "render/preview/preview_gpu.h"
#include "render/preview/voxel_programs.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace hp {
using Files = std::vector<std::pair<ShaderStage, std::string>>;

struct PreviewRenderer::Impl {
    PreviewSettings settings;
    PreviewStats stats;
    GlProgram strand, strandLines, strandShade, fur, head, headDepth, prefix, present;
    GlProgram resolveMs[2], resolveSs[2];  ///< [sorted]: sorted hair needs no accumulation or revealage
    /// Sorted hair that scatters nothing forward (Kajiya-Kay): the skin
    /// passes 1 - A, without resolve.frag's pow per sample and channel
    /// (~30 % of the resolve on llvmpipe); [multisampled], compiled on first use.
    GlProgram resolveOpaqueFibres[2];
    VoxelPrograms voxel;  ///< specialised for settings.shadow (voxel_programs.h)
    StrandBuffers strands;
    /// Sorted hair: the same strands as whole-strand patches for the light
    /// passes, which need no order (the voxel grid sums): a sixth of the
    /// sorted 4-segment patches at 24 vertices a strand, and llvmpipe's
    /// tessellation costs per patch (docs/benchmarks.md). Its own copy of
    /// the vertices (16 bytes each).
    StrandBuffers lightStrands;
    bool lightStrandsUsed = false;  ///< this frame's light passes draw lightStrands
    HeadBuffers headBuffers;
    RenderTargets targets;
    ShadowTargets shadows;
    CapturedPieces captured;
    std::vector<uint32_t> cpuVoxels[kMaxShadowedLights];  ///< VoxelizeOn::Cpu: each slot's grid (cpu_voxels.h)
    std::vector<uint32_t> cpuLinear;  ///< the same in the texture's order, when generated hair adds to it on the GPU
    std::vector<float> cpuDensity;    ///< a slot's density summed on the CPU, for its upload
    bool densityFromCpu = false;      ///< the last frame's densities were summed on the CPU (readVoxels)
    ShadedPoints shadedPoints;
    LinePieces linePieces;  ///< the thin strands' pieces from compute passes (line_pieces.h)
    GLuint cameraUbo = 0, emptyVao = 0, query = 0;
    GLuint lightUbo[kMaxShadowedLights] = {};  ///< one per shadowed light: its passes' grid
    GLsync fence = nullptr;
    int maxSamples = 1;
    bool pipelineStatistics = false;
    bool voxelsDrawn = false;
    std::vector<int> warnedUnfitted;  ///< lights already warned about
    int strandPatchSize = 0;
    bool thickStrands = true;  ///< some strand may be wider than the line path's width (the ribbon pass runs)
    bool strandsVisible = false, headVisible = false, furVisible = false;  // what this frame draws
    bool shadedPerFragment = false, shadedInCompute = false;
    std::vector<std::string> hairDefines, compiledHairDefines;  ///< this frame's lights and flags (hairShadingDefines)
    std::vector<ShadowSlot> slots;   ///< this frame's shadowed lights
    int slotResolution[kMaxShadowedLights] = {};

    explicit Impl(const PreviewSettings& s) : settings(s) {
        if (!epoxy_has_gl_extension("GL_ARB_shader_image_load_store") && epoxy_gl_version() < 42)
            throw Error("preview: the OpenGL driver lacks image load/store (needed for voxel shadows)");
        head = GlProgram("head", {{ShaderStage::Vertex, "head.vert"}, {ShaderStage::Fragment, "head.frag"}});
        headDepth = GlProgram("head shadow map", {{ShaderStage::Vertex, "head.vert"}, {ShaderStage::Fragment, "head.frag"}},
                              {"DEPTH_ONLY"});
        prefix = GlProgram("voxel sum", {{ShaderStage::Compute, "prefix.comp"}});
        const Files resolveStages = {{ShaderStage::Vertex, "fullscreen.vert"}, {ShaderStage::Fragment, "resolve.frag"}};
        resolveMs[0] = GlProgram("resolve (multisampled)", resolveStages, {"MULTISAMPLE"});
        resolveSs[0] = GlProgram("resolve", resolveStages);
        resolveMs[1] = GlProgram("resolve (multisampled, sorted)", resolveStages, {"MULTISAMPLE", "SORTED"});
        resolveSs[1] = GlProgram("resolve (sorted)", resolveStages, {"SORTED"});
        present = GlProgram("present", {{ShaderStage::Vertex, "fullscreen.vert"}, {ShaderStage::Fragment, "present.frag"}});

        strands.create();
        lightStrands.create();
        compileHairPrograms(std::min(strands.maxPatchVertices, 26));  // 24-vertex strands (docs/benchmarks.md)
        voxel.ensure(settings.shadow, strandPatchSize, 0);
        headBuffers.create();
        glCreateBuffers(1, &cameraUbo);
        glNamedBufferStorage(cameraUbo, sizeof(FrameUniforms), nullptr, GL_DYNAMIC_STORAGE_BIT);
        glCreateBuffers(kMaxShadowedLights, lightUbo);
        for (GLuint ubo : lightUbo) glNamedBufferStorage(ubo, sizeof(FrameUniforms), nullptr, GL_DYNAMIC_STORAGE_BIT);
        glCreateVertexArrays(1, &emptyVao);
        GLint samples = 1, colorSamples = 1, depthSamples = 1;
        glGetIntegerv(GL_MAX_SAMPLES, &samples);
        glGetIntegerv(GL_MAX_COLOR_TEXTURE_SAMPLES, &colorSamples);
        glGetIntegerv(GL_MAX_DEPTH_TEXTURE_SAMPLES, &depthSamples);
        maxSamples = std::max(1, std::min({samples, colorSamples, depthSamples}));
        pipelineStatistics = epoxy_gl_version() >= 46 || epoxy_has_gl_extension("GL_ARB_pipeline_statistics_query");
        if (pipelineStatistics) glGenQueries(1, &query);
        stats.renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    }

    ~Impl() {
        if (fence) glDeleteSync(fence);
        strands.destroy();
        lightStrands.destroy();
        headBuffers.destroy();
        targets.destroy();
        shadows.destroy();
        captured.destroy();
        shadedPoints.destroy();
        linePieces.destroy();
        glDeleteBuffers(1, &cameraUbo);
        glDeleteBuffers(kMaxShadowedLights, lightUbo);
        glDeleteVertexArrays(1, &emptyVao);
        if (query) glDeleteQueries(1, &query);
    }

    /// The hair programs are specialised for the strand patch size, the
    /// shading rate and the frame's lights and flags (hairDefines);
    /// recompiled when any changes.
    void compileHairPrograms(int patchSize) {
        const bool perFragment = settings.shadePerFragment;
        const bool inCompute = settings.shadeInCompute && !perFragment;
        const bool pieces = !perFragment && !inCompute && linePiecesInCompute(settings.piecesInCompute, stats.renderer);
        if (patchSize == strandPatchSize && perFragment == shadedPerFragment && inCompute == shadedInCompute &&
            hairDefines == compiledHairDefines && strand.id() && pieces == linePieces.compiled())
            return;
        std::vector<std::string> shading = perFragment ? std::vector<std::string>{"SHADE_PER_FRAGMENT"}
                                                       : std::vector<std::string>{};
        shading.insert(shading.end(), hairDefines.begin(), hairDefines.end());
        const Files stages = {{ShaderStage::Vertex, "strand.vert"},
                              {ShaderStage::TessControl, "strand.tesc"},
                              {ShaderStage::TessEvaluation, "strand.tese"}};
        std::vector<std::string> defines = shading;
        defines.push_back(cat("PATCH_SIZE ", patchSize));
        Files camera = stages, lines = stages;
        camera.push_back({ShaderStage::Geometry, "ribbon.geom"});
        camera.push_back({ShaderStage::Fragment, "hair.frag"});
        lines.push_back({ShaderStage::Fragment, "hair.frag"});
        std::vector<std::string> thick = defines, thin = defines;
        thick.push_back("THICK_PASS");
        thin.push_back("THIN_PASS");
        thin.push_back("LINE_OUTPUT");
        if (inCompute) {
            thick.push_back("SHADED_POINTS");
            thin.push_back("SHADED_POINTS");
            strandShade = GlProgram("strand point shading", {{ShaderStage::Compute, "strand_shade.comp"}}, defines);
        }
        strand = GlProgram("strand ribbons", camera, thick);
        strandLines = GlProgram("strand lines", lines, thin);
        linePieces.compile(pieces, defines, shading);
        fur = GlProgram("generated hair",
                        {{ShaderStage::Vertex, "fur.vert"},
                         {ShaderStage::TessControl, "fur.tesc"},
                         {ShaderStage::TessEvaluation, "fur.tese"},
                         {ShaderStage::Geometry, "fur.geom"},
                         {ShaderStage::Fragment, "hair.frag"}},
                        shading);
        strandPatchSize = patchSize;
        shadedPerFragment = perFragment;
        shadedInCompute = inCompute;
        compiledHairDefines = hairDefines;
    }

    /// Thin strands are drawn as lines of the minimum width when the
    /// rasterizer draws multisampled lines as exact rectangles of that width
    /// (GL spec 14.5.2.2), which keeps their coverage right.
    float linePathWidth() const {
        const float width = settings.minPixelWidth * float(supersample());
        if (samples() < 2) return 0.f;
        GLfloat range[2] = {1.f, 1.f};
        glGetFloatv(GL_SMOOTH_LINE_WIDTH_RANGE, range);
        return width >= range[0] && width <= range[1] ? width : 0.f;
    }

    int samples() const { return std::clamp(settings.msaa, 1, maxSamples); }
    int supersample() const { return std::clamp(settings.supersample, 1, 4); }

    void drawStrands(const GlProgram& program) { drawStrands(program, strands); }
    void drawStrands(const GlProgram& program, const StrandBuffers& b) {
        if (!strandsVisible || !b.indexCount) return;
        program.use();
        glBindVertexArray(b.vao);
        glPatchParameteri(GL_PATCH_VERTICES, b.patchSize);
        glDrawElements(GL_PATCHES, GLsizei(b.indexCount), GL_UNSIGNED_INT, nullptr);
    }

    void drawFur(const GlProgram& program) {
        if (!furVisible || !headBuffers.furIndexCount) return;
        program.use();
        glBindVertexArray(headBuffers.vao);
        glVertexArrayElementBuffer(headBuffers.vao, headBuffers.furIndices);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, headBuffers.furTypes);
        glBindTextureUnit(2, headBuffers.hairTypes);
        glPatchParameteri(GL_PATCH_VERTICES, 3);
        glDrawElements(GL_PATCHES, GLsizei(headBuffers.furIndexCount), GL_UNSIGNED_INT, nullptr);
    }

    void drawHead(const GlProgram& program) {
        if (!headVisible || !headBuffers.indexCount) return;
        program.use();
        glBindVertexArray(headBuffers.vao);
        glVertexArrayElementBuffer(headBuffers.vao, headBuffers.indices);
        glDrawElements(GL_TRIANGLES, GLsizei(headBuffers.indexCount), GL_UNSIGNED_INT, nullptr);
    }

    /// Each shadowed light in turn: its head shadow map layer, then the hair
    /// voxelized from it and summed along it into the slot's density grid.
    /// With shareTessellation the first slot's pass captures its strand
    /// pieces and the others draw those (one tessellation for all lights).
    void shadowPasses(bool mapOn, bool voxelsOn, bool onCpu, const StrandFrame* strandFrame) {
        const PreviewShadowSettings& sh = settings.shadow;
        const int n = int(slots.size());
        shadows.ensure(std::clamp(sh.shadowMapSize, 16, 16384), n, slotResolution);
        glDisable(GL_BLEND);
        const StrandBuffers& ls = lightStrandsUsed ? lightStrands : strands;
        const bool share = voxelsOn && sh.shareTessellation && n > 1 && strandsVisible && (ls.indexCount || onCpu);
        if (onCpu)  // VoxelizeOn::Cpu: every grid filled here, uploaded below (cpu_voxels.h)
            voxelizeSlotsOnCpu(strandsVisible ? strandFrame : nullptr, slots, slotResolution, settings,
                               strands.maxPatchVertices, share, cpuVoxels);
        else if (share)
            captured.ensure(lightPieceVertexBound(ls, *strandFrame, slots[0].grid, slotResolution[0],
                                                  std::clamp(settings.tessellationLevel, 1, 64),
                                                  settings.tessellationPixels * float(supersample()),
                                                  lightStrandsUsed ? kSortedPatchSegments : 0));
        densityFromCpu = onCpu && !furVisible;
        if (onCpu) mark("voxelize (CPU)");
        for (int k = 0; k < n; ++k) {
            glBindBufferBase(GL_UNIFORM_BUFFER, 0, lightUbo[k]);
            if (mapOn) {
                glBindFramebuffer(GL_FRAMEBUFFER, shadows.mapFbo[k]);
                glViewport(0, 0, shadows.mapSize, shadows.mapSize);
                glEnable(GL_DEPTH_TEST);
                glDepthFunc(GL_LESS);
                glDepthMask(GL_TRUE);
                const float one = 1.f;
                glClearNamedFramebufferfv(shadows.mapFbo[k], GL_DEPTH, 0, &one);
                glEnable(GL_POLYGON_OFFSET_FILL);
                glPolygonOffset(2.f, 4.f);
                drawHead(headDepth);
                glDisable(GL_POLYGON_OFFSET_FILL);
                mark("shadow map");
            }
            if (!voxelsOn) continue;
            const int res = slotResolution[k];
            if (densityFromCpu) {  // summed on the CPU too (no generated hair to add on the GPU)
                sumCpuVoxels(cpuVoxels[k], res, sh.sumAlongLight, cpuDensity);
                glTextureSubImage3D(shadows.density[k], 0, 0, 0, 0, res, res, res, GL_RED, GL_FLOAT, cpuDensity.data());
                mark("voxel sum (CPU) + upload");
                continue;
            }
            const GLuint zero = 0;
            if (onCpu) linearCpuVoxels(cpuVoxels[k], res, cpuLinear);
            if (onCpu)
                glTextureSubImage3D(shadows.voxels[k], 0, 0, 0, 0, res, res, res, GL_RED_INTEGER, GL_UNSIGNED_INT,
                                    cpuLinear.data());
            else
                glClearTexImage(shadows.voxels[k], 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
            mark(onCpu ? "voxel upload" : "voxel clear");
            glBindFramebuffer(GL_FRAMEBUFFER, shadows.voxelFbo);
            glViewport(0, 0, res, res);
            glDisable(GL_DEPTH_TEST);
            glDepthMask(GL_FALSE);
            glBindImageTexture(0, shadows.voxels[k], 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
            if (onCpu) {  // only generated hair is left to voxelize
            } else if (share && k == 0) {
                // The program is bound before capturing starts (GL forbids
                // changing it while transform feedback is active).
                voxel.strands.use();
                glBindVertexArray(ls.vao);
                glPatchParameteri(GL_PATCH_VERTICES, ls.patchSize);
                glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, captured.feedback);
                glBeginTransformFeedback(GL_LINES);
                glDrawElements(GL_PATCHES, GLsizei(ls.indexCount), GL_UNSIGNED_INT, nullptr);
                glEndTransformFeedback();
                glBindTransformFeedback(GL_TRANSFORM_FEEDBACK, 0);
            } else if (share) {
                voxel.captured.use();
                glBindVertexArray(captured.vao);
                glDrawTransformFeedback(GL_LINES, captured.feedback);
            } else {
                drawStrands(voxel.strands, ls);
            }
            drawFur(voxel.fur);
            glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
            mark("voxelize");
            prefix.use();
            glProgramUniform1i(prefix.id(), prefix.uniform("uSum"), sh.sumAlongLight ? 1 : 0);
            glProgramUniform1i(prefix.id(), prefix.uniform("uResolution"), res);
            glBindImageTexture(0, shadows.voxels[k], 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32UI);
            glBindImageTexture(1, shadows.density[k], 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
            const GLuint groups = GLuint((res + 7) / 8);
            glDispatchCompute(groups, groups, 1);
            glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                            GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
            mark("voxel sum");
        }
    }

    void cameraPass(bool voxelsOn, bool mapOn, float lineWidth) {
        glBindBufferBase(GL_UNIFORM_BUFFER, 0, cameraUbo);
        // Sorted hair: the head's depth from the camera (unit 9), where the camera
        // sees skin behind the hair (shaders/hair_shading.glsl skinBehindInView).
        const bool sorted = settings.blend == HairBlend::Sorted;
        const float far = 1.f;
        glDepthMask(GL_TRUE);  // the clear obeys it, and the light passes leave it off
        glClearNamedFramebufferfv(targets.headFbo, GL_DEPTH, 0, &far);
        glBindFramebuffer(GL_FRAMEBUFFER, sorted ? targets.headFbo : targets.msFbo);
        glViewport(0, 0, targets.width * targets.supersample, targets.height * targets.supersample);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        if (sorted) { drawHead(headDepth); mark("camera head depth"); }
        glBindTextureUnit(9, targets.headDepth);
        glBindFramebuffer(GL_FRAMEBUFFER, targets.msFbo);
        glViewport(0, 0, targets.width * targets.supersample, targets.height * targets.supersample);
        const float zero[4] = {0, 0, 0, 0}, one[4] = {1, 1, 1, 1};
        const float inf[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
        const GLenum all[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3};
        glDrawBuffers(4, all);
        glDisable(GL_BLEND);
        glDepthMask(GL_TRUE);
        glClearBufferfv(GL_COLOR, 0, zero);
        glClearBufferfv(GL_COLOR, 1, zero);  // weighted: accumulation; sorted: the skin
        if (settings.blend == HairBlend::Weighted) glClearBufferfv(GL_COLOR, 2, one);  // sorted hair reads no revealage
        glClearBufferfv(GL_COLOR, 3, inf);
        glClearBufferfv(GL_DEPTH, 0, one);
        mark("camera clear");
        // Units 4.. : each slot's density (uDensity[] in shaders/shadow.glsl); 1: the shadow maps.
        for (int k = 0; k < kMaxShadowedLights; ++k)
            glBindTextureUnit(GLuint(4 + k), voxelsOn && k < int(slots.size()) ? shadows.density[k] : shadows.dummyDensity);
        glBindTextureUnit(1, mapOn ? shadows.map : shadows.dummyMap);
        if (shadedInCompute && strandsVisible && strands.indexCount) {
            shadedPoints.shade(strands, strandShade);
            mark("strand point shading");
        }
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glEnable(GL_MULTISAMPLE);

        // Opaque head: colour into attachment 0 (sorted hair: into 1, kept apart
        // and seen through the hair in shaders/resolve.frag), nearest depth into 3.
        const GLenum none = GL_NONE;
        const GLenum opaque[] = {sorted ? none : GL_COLOR_ATTACHMENT0, sorted ? GL_COLOR_ATTACHMENT1 : none, none,
                                 GL_COLOR_ATTACHMENT3};
        glDrawBuffers(4, opaque);
        glEnablei(GL_BLEND, 3);
        glBlendEquationi(3, GL_MIN);
        glBlendFunci(3, GL_ONE, GL_ONE);
        drawHead(head);
        mark("head");

        // Hair: tested against the head's depth, never writing it; min depth
        // into 3. Sorted: premultiplied colour over attachment 0 (the patches
        // arrive back to front; its alpha is the hair's coverage, which the
        // resolve lets the skin through). Weighted: weighted sums into 1,
        // revealage products into 2.
        glDepthMask(GL_FALSE);
        if (sorted) {
            const GLenum hair[] = {GL_COLOR_ATTACHMENT0, GL_NONE, GL_NONE, GL_COLOR_ATTACHMENT3};
            glDrawBuffers(4, hair);
            glEnablei(GL_BLEND, 0);
            glBlendEquationi(0, GL_FUNC_ADD);
            glBlendFunci(0, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
        } else {
            const GLenum hair[] = {GL_NONE, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3};
            glDrawBuffers(4, hair);
            glEnablei(GL_BLEND, 1);
            glBlendEquationi(1, GL_FUNC_ADD);
            glBlendFunci(1, GL_ONE, GL_ONE);
            glEnablei(GL_BLEND, 2);
            glBlendEquationi(2, GL_FUNC_ADD);
            glBlendFunci(2, GL_ZERO, GL_ONE_MINUS_SRC_COLOR);
        }
        if (lineWidth > 0.f) {
            glLineWidth(lineWidth);
            if (linePieces.compiled() && strandsVisible) {
                linePieces.countPieces(strands);
                mark("strand pieces: count");
                linePieces.emitPieces();
                mark("strand pieces (compute)");
                linePieces.draw();
            } else
                drawStrands(strandLines);
            glLineWidth(1.f);
            mark("strand lines");
        }
        if (thickStrands) drawStrands(strand);
        mark("strand ribbons");
        if (query) glBeginQuery(GL_GEOMETRY_SHADER_INVOCATIONS, query);
        drawFur(fur);
        if (query) {
            glEndQuery(GL_GEOMETRY_SHADER_INVOCATIONS);
            GLuint64 invocations = 0;
            glGetQueryObjectui64v(query, GL_QUERY_RESULT, &invocations);
            stats.generatedStrands = size_t(invocations);
        }
        mark("generated hair");
        glDisable(GL_BLEND);
        glDepthMask(GL_TRUE);
    }

    void resolve(const View& view) {
        glBindFramebuffer(GL_FRAMEBUFFER, targets.resolvedFbo);
        glViewport(0, 0, targets.width, targets.height);
        glDisable(GL_DEPTH_TEST);
        glDisable(GL_BLEND);
        const int sorted = settings.blend == HairBlend::Sorted ? 1 : 0;
        const Vec3f af = skinForwardAlbedo(view.hair);  // what a fibre passes of the skin besides its gaps
        const bool opaqueFibres = sorted && af == Vec3f::Zero();
        const int ms = targets.samples > 1 ? 1 : 0;
        if (opaqueFibres && !resolveOpaqueFibres[ms].id()) {
            std::vector<std::string> defines = {"SORTED", "NO_FORWARD_SCATTERING"};
            if (ms) defines.push_back("MULTISAMPLE");
            resolveOpaqueFibres[ms] =
                GlProgram("resolve (sorted, no forward scattering)",
                          {{ShaderStage::Vertex, "fullscreen.vert"}, {ShaderStage::Fragment, "resolve.frag"}}, defines);
        }
        const GlProgram& p = opaqueFibres ? resolveOpaqueFibres[ms] : ms ? resolveMs[sorted] : resolveSs[sorted];
        p.use();
        glProgramUniform1i(p.id(), p.uniform("uSamples"), targets.samples);
        glProgramUniform1i(p.id(), p.uniform("uSupersample"), targets.supersample);
        // An environment map shows as its mean (render.environment_map).
        const Vec3f env = view.meanEnvironment();
        glProgramUniform3f(p.id(), p.uniform("uEnvironment"), env.x(), env.y(), env.z());
        if (sorted && !opaqueFibres) glProgramUniform3f(p.id(), p.uniform("uForward"), af.x(), af.y(), af.z());
        glBindTextureUnit(0, targets.opaque);
        glBindTextureUnit(1, targets.accum);
        glBindTextureUnit(2, targets.reveal);
        glBindTextureUnit(3, targets.minDepth);
        glBindVertexArray(emptyVao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }

    double lastWall = 0.0, lastCpu = 0.0, lastThread = 0.0;
    /// With settings.profile: finishes the GL work so far and records it as `pass`.
    void mark(const char* pass) {
        if (!settings.profile) return;
        glFinish();
        const double wall = wallMilliseconds(), cpu = cpuMilliseconds(), thread = threadCpuMilliseconds();
        if (pass) stats.passes.push_back({pass, wall - lastWall, cpu - lastCpu, thread - lastThread});
        lastWall = wall, lastCpu = cpu, lastThread = thread;
    }

    void draw(const View& view, const PreviewFrame& frame);
};

void PreviewRenderer::Impl::draw(const View& view, const PreviewFrame& frame) {
    if (fence) {
        // The previous frame may still read the mapped buffers we are about to overwrite.
        glClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, GLuint64(60) * 1000000000ull);
        glDeleteSync(fence);
        fence = nullptr;
    }
    while (glGetError() != GL_NO_ERROR) {
    }
    stats.passes.clear();
    mark(nullptr);
    const Camera& cam = view.camera;
    const bool drawStrandsNow = settings.drawStrands && frame.strands && frame.strands->vertexCount() > 0;
    const bool headNow = frame.head && !frame.head->triangles.empty();
    const bool headDrawn = headNow && settings.drawHead;
    Eigen::AlignedBox3f bounds;
    stats.strandSegments = 0;
    if (drawStrandsNow) {
        const bool sorted = settings.blend == HairBlend::Sorted;
        strands.upload(*frame.strands, sorted ? kSortedPatchSegments : 0);
        if (sorted)
            strands.sortBackToFront(*frame.strands, cam.position, (cam.target - cam.position).normalized());
        compileHairPrograms(strands.patchSize);
        stats.strandSegments = strands.segments;
        for (const Vec3f& p : frame.strands->positions) bounds.extend(p);
    }
    strandsVisible = drawStrandsNow;
    std::vector<uint8_t> types;
    if (headNow) {
        if (settings.generated.enabled) {
            try {
                types = assignHairTypes(*frame.head, settings.generated, frame.headTransform.inverse(), frame.scalpMask);
            } catch (const FrameError&) {
                throw;
            } catch (const Error& e) {
                throw FrameError(cat("preview: ", e.what()));
            }
        }
        headBuffers.upload(*frame.head, types, settings.generated.types);
        Eigen::AlignedBox3f hb = frame.head->bounds();
        if (settings.generated.enabled && headBuffers.furIndexCount) {
            const float pad = settings.generated.maxLength();
            hb.extend(hb.min() - Vec3f::Constant(pad));
            hb.extend(hb.max() + Vec3f::Constant(pad));
        }
        bounds.extend(hb);
    }
    headVisible = headDrawn;
    furVisible = headNow && settings.generated.enabled && headBuffers.furIndexCount > 0;
    stats.furTriangles = furVisible ? headBuffers.furIndexCount / 3 : 0;
    stats.generatedStrands = 0;

    mark("upload");

    // Reference depth of the blend weights: the scene's nearest bound corner.
    float blendReference = cam.nearClip;
    if (!bounds.isEmpty()) {
        float nearest = INFINITY;
        const Mat4f viewM = cam.view();
        for (int i = 0; i < 8; ++i)
            nearest = std::min(nearest, -(viewM * bounds.corner(Eigen::AlignedBox3f::CornerType(i)).homogeneous()).z());
        blendReference = std::max(nearest, cam.nearClip);
    }

    const PreviewShadowSettings& sh = settings.shadow;
    slots.clear();
    if ((sh.voxels || sh.shadowMap) && !bounds.isEmpty()) {
        std::vector<int> unfitted;
        slots = fitShadowSlots(view.lights, std::clamp(sh.maxLights, 0, kMaxShadowedLights), bounds, &unfitted);
        for (int light : unfitted) {
            if (std::find(warnedUnfitted.begin(), warnedUnfitted.end(), light) != warnedUnfitted.end()) continue;
            logWarning("preview: render.lights[", light,
                       "] is a point light inside the scene's bounds; it casts no shadows in the preview");
            warnedUnfitted.push_back(light);
        }
    }
    for (size_t k = 0; k < slots.size(); ++k) {
        const int res = k == 0 || sh.otherResolution <= 0 ? sh.resolution : sh.otherResolution;
        slotResolution[k] = std::clamp(res, 4, 1024);
    }
    stats.shadowed = !slots.empty();
    stats.shadowedLights = int(slots.size());
    const bool voxelsOn = !slots.empty() && sh.voxels;
    const bool mapOn = !slots.empty() && sh.shadowMap && headDrawn;
    voxelsDrawn = voxelsOn;

    FrameUniforms u;
    fillFrameUniforms(u, UniformInputs{view, settings, frame, blendReference, supersample(), slots, slotResolution,
                                       voxelsOn, mapOn});
    const float lineWidth = linePathWidth();
    u.blend[2] = lineWidth > 0.f ? 1.f : 0.f;
    thickStrands = drawStrandsNow && mayHaveThickStrands(*frame.strands, Eigen::Map<const Mat4f>(u.viewProj),
                                                         u.eye[3], lineWidth > 0.f ? u.tess[3] : 0.f);
    glNamedBufferSubData(cameraUbo, 0, sizeof(u), &u);
    hairDefines = settings.specializeShading ? hairShadingDefines(u) : std::vector<std::string>{};
    compileHairPrograms(strandPatchSize);  // follows a changed shading rate, lights or hair model
    const bool onCpu = voxelsOn && voxelizeOnCpu(sh.voxelize, stats.renderer);
    lightStrandsUsed = voxelsOn && !onCpu && drawStrandsNow && settings.blend == HairBlend::Sorted;
    if (lightStrandsUsed) lightStrands.upload(*frame.strands, 0);
    // Follows a changed patch size or voxel settings. The whole strands are
    // cut into at least a piece per kSortedPatchSegments segments, as many as
    // the sorted patches would give (fewer bend the grid's hair off the curve).
    voxel.ensure(settings.shadow, lightStrandsUsed ? lightStrands.patchSize : strandPatchSize,
                 lightStrandsUsed ? kSortedPatchSegments : 0);
    if (voxelsOn || mapOn) {
        for (size_t k = 0; k < slots.size(); ++k) {
            FrameUniforms l = u;
            setPassGrid(l, slots[k].grid, slotResolution[k]);
            glNamedBufferSubData(lightUbo[k], 0, sizeof(l), &l);
        }
        shadowPasses(mapOn, voxelsOn, onCpu, frame.strands);
    }
    targets.ensure(cam.width, cam.height, samples(), supersample());
    cameraPass(voxelsOn, mapOn, lineWidth);
    resolve(view);
    mark("resolve");
    fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    const GLenum error = glGetError();
    if (error != GL_NO_ERROR)
        throw FrameError(cat("preview: OpenGL error 0x", std::hex, error, " while drawing (", stats.renderer, ")"));
}

PreviewRenderer::PreviewRenderer(const PreviewSettings& settings) : impl_(std::make_unique<Impl>(settings)) {}
PreviewRenderer::~PreviewRenderer() = default;

const PreviewSettings& PreviewRenderer::settings() const { return impl_->settings; }
void PreviewRenderer::setSettings(const PreviewSettings& settings) { impl_->settings = settings; }
const PreviewStats& PreviewRenderer::stats() const { return impl_->stats; }

void PreviewRenderer::draw(const View& shotView, const PreviewFrame& frame) {
    View view = shotView;
    view.lights = shotView.worldLights();  // a camera-relative rig follows this frame's camera
    impl_->draw(view, frame);
}

void PreviewRenderer::finish() const { glFinish(); }

Image PreviewRenderer::render(const View& view, const PreviewFrame& frame) {
    draw(view, frame);
    return readback();
}

Image PreviewRenderer::readback() const { return impl_->targets.read(); }

void PreviewRenderer::present(int x, int y, int width, int height) const {
    const Impl& m = *impl_;
    if (!m.targets.resolvedFbo) return;
    glViewport(x, y, width, height);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    m.present.use();
    glProgramUniform4i(m.present.id(), m.present.uniform("uRect"), x, y, width, height);
    glBindTextureUnit(0, m.targets.resolvedColor);
    glBindVertexArray(m.emptyVao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

VoxelSnapshot PreviewRenderer::readVoxels(int slot) const {
    const Impl& m = *impl_;
    VoxelSnapshot snap;
    if (!m.voxelsDrawn || slot < 0 || size_t(slot) >= m.slots.size()) return snap;
    snap.resolution = m.slotResolution[slot];
    snap.grid = m.slots[size_t(slot)].grid;
    snap.raw = m.densityFromCpu ? cpuVoxelValues(m.cpuVoxels[slot], snap.resolution) : m.shadows.readRaw(slot);
    snap.summed = m.shadows.readSummed(slot);
    return snap;
}

}  // namespace hp
