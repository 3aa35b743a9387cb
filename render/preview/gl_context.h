// A headless OpenGL 4.5 core context through EGL, for the preview pass.
//
// No window, no display server: Mesa's surfaceless platform (llvmpipe where
// there is no GPU), the EGL device platform (vendor drivers such as NVIDIA's),
// or the default display, in that order. GL headers stay in the .cpp files.
#pragma once

#include <memory>
#include <string>

namespace hp {

/// True when GL_RENDERER names a software rasterizer (llvmpipe, softpipe,
/// swrast): the preview then does on the CPU, or in compute passes, the
/// work such a renderer runs on one thread.
bool softwareRasterizer(const std::string& renderer);

/// Owns an EGL display and an OpenGL 4.5 core context with no surface
/// (rendering goes to framebuffer objects).
class GlContext {
  public:
    /// Creates the context and makes it current on the calling thread.
    ///
    /// Tries, in order: eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA),
    /// every device of EGL_EXT_platform_device, then eglGetDisplay(EGL_DEFAULT_DISPLAY).
    /// The first candidate that gives a 4.5 core context wins, except that a
    /// software rasterizer (llvmpipe, softpipe) is only kept when no later
    /// candidate gives a hardware one. Throws hp::Error naming every attempt
    /// and why it failed when none works.
    static std::unique_ptr<GlContext> createHeadless();

    ~GlContext();
    GlContext(const GlContext&) = delete;
    GlContext& operator=(const GlContext&) = delete;

    /// Makes the context current on the calling thread (it is current after creation).
    void makeCurrent();
    /// "llvmpipe (LLVM 15.0.6, 256 bits) | 4.5 (Core Profile) Mesa 22.3.6 | EGL surfaceless".
    const std::string& description() const;
    /// True for software rasterizers (llvmpipe, softpipe, swrast).
    bool software() const;

  private:
    struct Impl;
    explicit GlContext(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace hp
