// Framebuffers and textures of the preview: the camera pass's multisampled
// target, the resolved image, and the shadow map and voxel grids.
#include "render/preview/preview_gpu.h"

#include "core/errors.h"

#include <epoxy/gl.h>

#include <algorithm>

namespace hp {

namespace {

GLuint makeTarget(int w, int h, int samples, GLenum format) {
    GLuint tex = 0;
    if (samples > 1) {
        glCreateTextures(GL_TEXTURE_2D_MULTISAMPLE, 1, &tex);
        glTextureStorage2DMultisample(tex, samples, format, w, h, GL_TRUE);
    } else {
        glCreateTextures(GL_TEXTURE_2D, 1, &tex);
        glTextureStorage2D(tex, 1, format, w, h);
        glTextureParameteri(tex, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(tex, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    return tex;
}

void checkComplete(GLuint fbo, const char* what) {
    const GLenum status = glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER);
    if (status != GL_FRAMEBUFFER_COMPLETE)
        throw FrameError(cat("preview: the ", what, " framebuffer is incomplete (status 0x", std::hex, status, ")"));
}

void deleteTextures(std::initializer_list<unsigned*> list) {
    for (unsigned* t : list) {
        if (*t) glDeleteTextures(1, t);
        *t = 0;
    }
}

void deleteFramebuffers(std::initializer_list<unsigned*> list) {
    for (unsigned* f : list) {
        if (*f) glDeleteFramebuffers(1, f);
        *f = 0;
    }
}

}  // namespace

void RenderTargets::ensure(int w, int h, int s, int ss) {
    if (w == width && h == height && s == samples && ss == supersample && msFbo) return;
    destroy();
    width = w, height = h, samples = s, supersample = ss;
    const int tw = w * ss, th = h * ss;
    opaque = makeTarget(tw, th, s, GL_RGBA32F);  // sorted hair blends into it: half floats drift over many faint strands
    accum = makeTarget(tw, th, s, GL_RGBA32F);
    reveal = makeTarget(tw, th, s, GL_R32F);
    minDepth = makeTarget(tw, th, s, GL_R32F);
    depth = makeTarget(tw, th, s, GL_DEPTH_COMPONENT32F);
    glCreateFramebuffers(1, &msFbo);
    glNamedFramebufferTexture(msFbo, GL_COLOR_ATTACHMENT0, opaque, 0);
    glNamedFramebufferTexture(msFbo, GL_COLOR_ATTACHMENT1, accum, 0);
    glNamedFramebufferTexture(msFbo, GL_COLOR_ATTACHMENT2, reveal, 0);
    glNamedFramebufferTexture(msFbo, GL_COLOR_ATTACHMENT3, minDepth, 0);
    glNamedFramebufferTexture(msFbo, GL_DEPTH_ATTACHMENT, depth, 0);
    checkComplete(msFbo, "multisampled camera");

    resolvedColor = makeTarget(w, h, 1, GL_RGBA32F);
    glTextureParameteri(resolvedColor, GL_TEXTURE_MIN_FILTER, GL_LINEAR);  // the viewer scales it
    glTextureParameteri(resolvedColor, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    resolvedDepth = makeTarget(w, h, 1, GL_R32F);
    glCreateFramebuffers(1, &resolvedFbo);
    glNamedFramebufferTexture(resolvedFbo, GL_COLOR_ATTACHMENT0, resolvedColor, 0);
    glNamedFramebufferTexture(resolvedFbo, GL_COLOR_ATTACHMENT1, resolvedDepth, 0);
    const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glNamedFramebufferDrawBuffers(resolvedFbo, 2, buffers);
    checkComplete(resolvedFbo, "resolved");

    headDepth = makeTarget(tw, th, 1, GL_DEPTH_COMPONENT32F);
    glTextureParameteri(headDepth, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(headDepth, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(headDepth, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(headDepth, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glCreateFramebuffers(1, &headFbo);
    glNamedFramebufferTexture(headFbo, GL_DEPTH_ATTACHMENT, headDepth, 0);
    glNamedFramebufferDrawBuffer(headFbo, GL_NONE);
    checkComplete(headFbo, "camera head depth");
}

Image RenderTargets::read() const {
    if (!resolvedFbo) throw FrameError("preview: nothing drawn yet");
    const int w = width, h = height;
    std::vector<float> rgba(size_t(w) * h * 4), z(size_t(w) * h);
    glGetTextureImage(resolvedColor, 0, GL_RGBA, GL_FLOAT, GLsizei(rgba.size() * sizeof(float)), rgba.data());
    glGetTextureImage(resolvedDepth, 0, GL_RED, GL_FLOAT, GLsizei(z.size() * sizeof(float)), z.data());
    Image image(w, h, {"R", "G", "B", "A", "Z"});
    for (int y = 0; y < h; ++y) {
        const size_t src = size_t(h - 1 - y) * w;  // GL rows start at the bottom
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < 4; ++c) image.at(x, y, c) = rgba[(src + x) * 4 + c];
            image.at(x, y, 4) = z[src + x];
        }
    }
    return image;
}

void RenderTargets::destroy() {
    deleteFramebuffers({&msFbo, &resolvedFbo, &headFbo});
    deleteTextures({&opaque, &accum, &reveal, &minDepth, &depth, &resolvedColor, &resolvedDepth, &headDepth});
    width = height = samples = supersample = 0;
}

void ShadowTargets::ensure(int size, int slots, const int* resolutions) {
    if (!dummyDensity) {
        // Bound when a shadow kind is off, so every sampler always sees a complete texture.
        const float zero = 0.f, one = 1.f;
        glCreateTextures(GL_TEXTURE_3D, 1, &dummyDensity);
        glTextureStorage3D(dummyDensity, 1, GL_R32F, 1, 1, 1);
        glTextureSubImage3D(dummyDensity, 0, 0, 0, 0, 1, 1, 1, GL_RED, GL_FLOAT, &zero);
        glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &dummyMap);
        glTextureStorage3D(dummyMap, 1, GL_DEPTH_COMPONENT32F, 1, 1, 1);
        glTextureSubImage3D(dummyMap, 0, 0, 0, 0, 1, 1, 1, GL_DEPTH_COMPONENT, GL_FLOAT, &one);
        glTextureParameteri(dummyMap, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    }
    slots = std::clamp(slots, 1, kMaxShadowedLights);
    if (size != mapSize || slots > mapLayers) {
        deleteFramebuffers({&mapFbo[0], &mapFbo[1], &mapFbo[2], &mapFbo[3]});
        deleteTextures({&map});
        mapSize = size;
        mapLayers = slots;
        glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &map);
        glTextureStorage3D(map, 1, GL_DEPTH_COMPONENT32F, size, size, slots);
        glTextureParameteri(map, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(map, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        glTextureParameteri(map, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTextureParameteri(map, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glTextureParameteri(map, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
        glTextureParameteri(map, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
        for (int k = 0; k < slots; ++k) {
            glCreateFramebuffers(1, &mapFbo[k]);
            glNamedFramebufferTextureLayer(mapFbo[k], GL_DEPTH_ATTACHMENT, map, 0, k);
            glNamedFramebufferDrawBuffer(mapFbo[k], GL_NONE);
            checkComplete(mapFbo[k], "shadow map");
        }
    }
    int largest = 0;
    for (int k = 0; k < slots; ++k) largest = std::max(largest, resolutions[k]);
    if (largest > fboSize) {
        // Voxelization writes through image atomics only: a framebuffer with
        // no attachments gives the rasterizer its viewport (each slot's
        // resolution, at most this).
        deleteFramebuffers({&voxelFbo});
        fboSize = largest;
        glCreateFramebuffers(1, &voxelFbo);
        glNamedFramebufferParameteri(voxelFbo, GL_FRAMEBUFFER_DEFAULT_WIDTH, largest);
        glNamedFramebufferParameteri(voxelFbo, GL_FRAMEBUFFER_DEFAULT_HEIGHT, largest);
        checkComplete(voxelFbo, "voxelization");
    }
    for (int k = 0; k < slots; ++k) {
        const int res = resolutions[k];
        if (res == resolution[k] && density[k]) continue;
        deleteTextures({&density[k], &voxels[k]});
        resolution[k] = res;
        // Each slot its own voxel grid: the first slot's pass captures the
        // pieces the others draw, so it runs first (8 MB more a 128³ slot).
        glCreateTextures(GL_TEXTURE_3D, 1, &voxels[k]);
        glTextureStorage3D(voxels[k], 1, GL_R32UI, res, res, res);
        glCreateTextures(GL_TEXTURE_3D, 1, &density[k]);
        glTextureStorage3D(density[k], 1, GL_R32F, res, res, res);
        glTextureParameteri(density[k], GL_TEXTURE_MIN_FILTER, GL_LINEAR);
        glTextureParameteri(density[k], GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
            glTextureParameteri(density[k], wrap, GL_CLAMP_TO_EDGE);
    }
}

std::vector<float> ShadowTargets::readRaw(int k) const {
    const size_t n = size_t(resolution[k]) * size_t(resolution[k]) * size_t(resolution[k]);
    std::vector<uint32_t> units(n);
    glGetTextureImage(voxels[k], 0, GL_RED_INTEGER, GL_UNSIGNED_INT, GLsizei(n * 4), units.data());
    std::vector<float> raw(n);
    for (size_t i = 0; i < n; ++i) raw[i] = float(units[i]) / kVoxelUnit;
    return raw;
}

std::vector<float> ShadowTargets::readSummed(int k) const {
    const size_t n = size_t(resolution[k]) * size_t(resolution[k]) * size_t(resolution[k]);
    std::vector<float> summed(n);
    glGetTextureImage(density[k], 0, GL_RED, GL_FLOAT, GLsizei(n * 4), summed.data());
    return summed;
}

void ShadowTargets::destroy() {
    deleteFramebuffers({&mapFbo[0], &mapFbo[1], &mapFbo[2], &mapFbo[3], &voxelFbo});
    deleteTextures({&map, &voxels[0], &voxels[1], &voxels[2], &voxels[3], &density[0], &density[1], &density[2],
                    &density[3], &dummyDensity, &dummyMap});
    mapSize = mapLayers = fboSize = 0;
    for (int& r : resolution) r = 0;
}

void CapturedPieces::ensure(size_t vertices) {
    if (!feedback) {
        glCreateTransformFeedbacks(1, &feedback);
        // The captured vertices as shaders/voxel_lines.vert reads them.
        glCreateVertexArrays(1, &vao);
        const GLuint offsets[] = {0, 12, 24}, sizes[] = {3, 3, 1};
        for (GLuint a = 0; a < 3; ++a) {
            glEnableVertexArrayAttrib(vao, a);
            glVertexArrayAttribFormat(vao, a, GLint(sizes[a]), GL_FLOAT, GL_FALSE, offsets[a]);
            glVertexArrayAttribBinding(vao, a, 0);
        }
    }
    const size_t bytes = std::max<size_t>(vertices, 2) * kVertexBytes;
    if (bytes <= capacity && buffer) return;
    if (buffer) glDeleteBuffers(1, &buffer);
    capacity = std::max(bytes, capacity + capacity / 2);  // grow by half again, as PersistentBuffer
    glCreateBuffers(1, &buffer);
    glNamedBufferStorage(buffer, GLsizeiptr(capacity), nullptr, 0);
    glTransformFeedbackBufferBase(feedback, 0, buffer);
    glVertexArrayVertexBuffer(vao, 0, buffer, 0, GLsizei(kVertexBytes));
}

void CapturedPieces::destroy() {
    if (buffer) glDeleteBuffers(1, &buffer);
    if (feedback) glDeleteTransformFeedbacks(1, &feedback);
    if (vao) glDeleteVertexArrays(1, &vao);
    buffer = feedback = vao = 0;
    capacity = 0;
}

}  // namespace hp
