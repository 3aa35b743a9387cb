#include "render/preview/gl_context.h"

#include "core/errors.h"
#include "core/log.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>

#include <cstdlib>
#include <cstring>
#include <functional>
#include <vector>

namespace hp {

namespace {

/// One EGL display with its context; released in reverse order.
struct EglState {
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
    EGLSurface surface = EGL_NO_SURFACE;  // a 16x16 pbuffer only where surfaceless contexts are missing
    std::string description;
    bool software = false;

    ~EglState() {
        if (display == EGL_NO_DISPLAY) return;
        eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (context != EGL_NO_CONTEXT) eglDestroyContext(display, context);
        if (surface != EGL_NO_SURFACE) eglDestroySurface(display, surface);
#ifndef HAIRPIPE_SANITIZE
        eglTerminate(display);
#else
        // Sanitizer build (cmake/Sanitizers.cmake): eglTerminate unloads
        // Mesa's driver, and LeakSanitizer then reports an allocation the
        // driver still held, from an "<unknown module>" that no suppression
        // can name. Left loaded, the memory stays reachable and nothing is
        // reported; the process exit releases it either way.
#endif
    }
};

bool hasExtension(const char* list, const char* name) {
    if (!list) return false;
    const size_t n = std::strlen(name);
    for (const char* p = list; (p = std::strstr(p, name)); p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
    return false;
}

std::string eglErrorText() {
    return cat("EGL error 0x", std::hex, eglGetError());
}

/// One display to try: a name for messages and how to open it.
struct Candidate {
    std::string name;
    std::function<EGLDisplay()> open;
};

std::vector<Candidate> candidates() {
    std::vector<Candidate> list;
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    const bool platformCall = hasExtension(client, "EGL_EXT_platform_base");
    const char* only = std::getenv("HAIRPIPE_GL_PLATFORM");  // debugging: surfaceless | device | default
    auto wanted = [&](const char* kind) { return !only || !*only || std::strcmp(only, kind) == 0; };

    if (wanted("surfaceless") && platformCall && hasExtension(client, "EGL_MESA_platform_surfaceless"))
        list.push_back({"EGL surfaceless (Mesa)", [] {
                            return eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY,
                                                            nullptr);
                        }});
    if (wanted("device") && platformCall && hasExtension(client, "EGL_EXT_platform_device") &&
        hasExtension(client, "EGL_EXT_device_enumeration")) {
        EGLint count = 0;
        eglQueryDevicesEXT(0, nullptr, &count);
        std::vector<EGLDeviceEXT> devices(size_t(std::max(count, 0)));
        if (count > 0) eglQueryDevicesEXT(count, devices.data(), &count);
        for (EGLint i = 0; i < count; ++i) {
            EGLDeviceEXT device = devices[size_t(i)];
            // Mesa lists its software rasterizer as a device too; surfaceless already covers it.
            if (hasExtension(eglQueryDeviceStringEXT(device, EGL_EXTENSIONS), "EGL_MESA_device_software")) continue;
            list.push_back({cat("EGL device ", i), [device] {
                                return eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, device, nullptr);
                            }});
        }
    }
    if (wanted("default")) list.push_back({"eglGetDisplay(EGL_DEFAULT_DISPLAY)", [] {
                                               return eglGetDisplay(EGL_DEFAULT_DISPLAY);
                                           }});
    return list;
}

/// Opens one candidate; returns null and sets `why` when it gives no 4.5 core context.
std::unique_ptr<EglState> tryCandidate(const Candidate& c, std::string& why) {
    auto impl = std::make_unique<EglState>();
    EGLDisplay display = c.open();
    if (display == EGL_NO_DISPLAY) {
        why = "no display (" + eglErrorText() + ")";
        return nullptr;
    }
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) {
        why = "eglInitialize failed (" + eglErrorText() + ")";
        return nullptr;
    }
    impl->display = display;  // from here the destructor terminates it
    if (!eglBindAPI(EGL_OPENGL_API)) {
        why = "desktop OpenGL not supported by this EGL (" + eglErrorText() + ")";
        return nullptr;
    }
    const char* ext = eglQueryString(display, EGL_EXTENSIONS);
    const bool surfaceless = hasExtension(ext, "EGL_KHR_surfaceless_context");

    // Surfaceless platforms list configs only for pbuffers (Mesa's surfaceless
    // EGL returns no config unless EGL_SURFACE_TYPE asks for EGL_PBUFFER_BIT;
    // EGL_NO_CONFIG_KHR is the other way); the colour format does not matter
    // since all rendering goes to FBOs.
    const EGLint configAttribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint configs = 0;
    if (!eglChooseConfig(display, configAttribs, &config, 1, &configs) || configs < 1) {
        if (!(surfaceless && hasExtension(ext, "EGL_KHR_no_config_context"))) {
            why = "no OpenGL pbuffer config";
            return nullptr;
        }
        config = EGL_NO_CONFIG_KHR;
    }
    const EGLint contextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION_KHR, 4, EGL_CONTEXT_MINOR_VERSION_KHR, 5,
                                     EGL_CONTEXT_OPENGL_PROFILE_MASK_KHR,
                                     EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT_KHR, EGL_NONE};
    impl->context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttribs);
    if (impl->context == EGL_NO_CONTEXT) {
        why = "no OpenGL 4.5 core context (" + eglErrorText() + ")";
        return nullptr;
    }
    if (!surfaceless) {
        const EGLint pbufferAttribs[] = {EGL_WIDTH, 16, EGL_HEIGHT, 16, EGL_NONE};
        impl->surface = config ? eglCreatePbufferSurface(display, config, pbufferAttribs) : EGL_NO_SURFACE;
        if (impl->surface == EGL_NO_SURFACE) {
            why = "neither surfaceless contexts nor a pbuffer (" + eglErrorText() + ")";
            return nullptr;
        }
    }
    if (!eglMakeCurrent(display, impl->surface, impl->surface, impl->context)) {
        why = "eglMakeCurrent failed (" + eglErrorText() + ")";
        return nullptr;
    }
    GLint glMajor = 0, glMinor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &glMajor);
    glGetIntegerv(GL_MINOR_VERSION, &glMinor);
    const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    if (glMajor * 10 + glMinor < 45) {
        why = cat("OpenGL ", glMajor, ".", glMinor, " < 4.5 (", renderer ? renderer : "?", ")");
        return nullptr;
    }
    const std::string r = renderer ? renderer : "unknown renderer";
    impl->software = softwareRasterizer(r);
    impl->description = cat(r, " | ", version ? version : "?", " | ", c.name);
    return impl;
}

}  // namespace

struct GlContext::Impl {
    std::unique_ptr<EglState> egl;
};

GlContext::GlContext(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GlContext::~GlContext() = default;

std::unique_ptr<GlContext> GlContext::createHeadless() {
    std::vector<std::string> tried;
    std::unique_ptr<EglState> software;  // kept while a hardware context is looked for
    for (const Candidate& c : candidates()) {
        std::string why;
        std::unique_ptr<EglState> impl = tryCandidate(c, why);
        if (!impl) {
            tried.push_back(c.name + ": " + why);
            continue;
        }
        if (!impl->software) {
            software.reset();
            logVerbose("preview: OpenGL ", impl->description);
            std::unique_ptr<GlContext> ctx(new GlContext(std::make_unique<Impl>(Impl{std::move(impl)})));
            ctx->makeCurrent();
            return ctx;
        }
        tried.push_back(c.name + ": software renderer, looking further for a GPU");
        if (!software) software = std::move(impl);
    }
    if (software) {
        logVerbose("preview: OpenGL ", software->description);
        std::unique_ptr<GlContext> ctx(new GlContext(std::make_unique<Impl>(Impl{std::move(software)})));
        ctx->makeCurrent();
        return ctx;
    }
    std::string message = "no usable headless OpenGL 4.5 core context through EGL; tried:";
    if (tried.empty()) message += " nothing (this EGL offers no platform hairpipe can use)";
    for (const std::string& t : tried) message += "\n  - " + t;
    message += "\n(install Mesa's EGL driver, Debian packages libegl-mesa0 libgl1-mesa-dri, or a vendor driver)";
    throw Error(message);
}

void GlContext::makeCurrent() {
    const EglState& e = *impl_->egl;
    if (!eglMakeCurrent(e.display, e.surface, e.surface, e.context))
        throw Error("cannot make the preview's OpenGL context current (" + eglErrorText() + ")");
}

const std::string& GlContext::description() const { return impl_->egl->description; }
bool softwareRasterizer(const std::string& renderer) {
    for (const char* name : {"llvmpipe", "softpipe", "swrast"})
        if (renderer.find(name) != std::string::npos) return true;
    return false;
}

bool GlContext::software() const { return impl_->egl->software; }

}  // namespace hp
