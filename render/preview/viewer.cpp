#include "render/preview/viewer.h"

#include "core/errors.h"
#include "core/log.h"

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>

namespace hp {

namespace {

/// Orbit camera around the view's target: yaw/pitch in radians, distance in metres.
struct Orbit {
    float yaw = 0.f, pitch = 0.f, distance = 1.f;

    static Orbit from(const Camera& c) {
        const Vec3f d = c.position - c.target;
        Orbit o;
        o.distance = d.norm();
        o.yaw = std::atan2(d.x(), d.z());
        o.pitch = std::asin(std::clamp(d.y() / o.distance, -1.f, 1.f));
        return o;
    }

    Vec3f position(const Vec3f& target) const {
        return target + distance * Vec3f(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
    }
};

struct ViewerState {
    View view;
    PreviewSettings settings;
    Orbit orbit, initialOrbit;
    size_t frameIndex = 0;
    bool playing = true;
    bool settingsChanged = false;
    bool dragging = false;
    double lastX = 0.0, lastY = 0.0;
};

const char* voxelModeName(const PreviewShadowSettings& s) {
    if (s.mode == VoxelMode::Binary) return "binary/nearest";
    return s.splat == VoxelSplat::Trilinear ? "additive/trilinear" : "additive/nearest";
}

void onKey(GLFWwindow* window, int key, int, int action, int) {
    if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
    auto* st = static_cast<ViewerState*>(glfwGetWindowUserPointer(window));
    PreviewSettings& s = st->settings;
    PreviewShadowSettings& sh = s.shadow;
    switch (key) {
        case GLFW_KEY_ESCAPE:
        case GLFW_KEY_Q: glfwSetWindowShouldClose(window, GLFW_TRUE); return;
        case GLFW_KEY_SPACE: st->playing = !st->playing; return;
        case GLFW_KEY_RIGHT: st->playing = false, ++st->frameIndex; return;
        case GLFW_KEY_LEFT: st->playing = false, st->frameIndex = st->frameIndex ? st->frameIndex - 1 : 0; return;
        case GLFW_KEY_HOME: st->frameIndex = 0; return;
        case GLFW_KEY_END: st->frameIndex = size_t(-1); return;
        case GLFW_KEY_R: st->orbit = st->initialOrbit; return;
        case GLFW_KEY_V: sh.voxels = !sh.voxels; break;
        case GLFW_KEY_M: sh.shadowMap = !sh.shadowMap; break;
        case GLFW_KEY_S: sh.sumAlongLight = !sh.sumAlongLight; break;
        case GLFW_KEY_X: sh.filter = !sh.filter; break;
        case GLFW_KEY_G: s.generated.enabled = !s.generated.enabled; break;
        case GLFW_KEY_H: s.drawHead = !s.drawHead; break;
        case GLFW_KEY_F: s.shadePerFragment = !s.shadePerFragment; break;
        case GLFW_KEY_B:  // Dehlin and Styngberg's three voxelizations, in turn
            if (sh.mode == VoxelMode::Binary) sh.mode = VoxelMode::Additive, sh.splat = VoxelSplat::Nearest;
            else if (sh.splat == VoxelSplat::Nearest) sh.splat = VoxelSplat::Trilinear;
            else sh.mode = VoxelMode::Binary, sh.splat = VoxelSplat::Nearest;
            break;
        default: return;
    }
    st->settingsChanged = true;
}

void onButton(GLFWwindow* window, int button, int action, int) {
    auto* st = static_cast<ViewerState*>(glfwGetWindowUserPointer(window));
    if (button != GLFW_MOUSE_BUTTON_LEFT) return;
    st->dragging = action == GLFW_PRESS;
    glfwGetCursorPos(window, &st->lastX, &st->lastY);
}

void onCursor(GLFWwindow* window, double x, double y) {
    auto* st = static_cast<ViewerState*>(glfwGetWindowUserPointer(window));
    if (!st->dragging) return;
    st->orbit.yaw -= float(x - st->lastX) * 0.01f;
    st->orbit.pitch = std::clamp(st->orbit.pitch + float(y - st->lastY) * 0.01f, -1.5f, 1.5f);
    st->lastX = x, st->lastY = y;
}

void onScroll(GLFWwindow* window, double, double dy) {
    auto* st = static_cast<ViewerState*>(glfwGetWindowUserPointer(window));
    st->orbit.distance = std::max(0.01f, st->orbit.distance * std::pow(0.9f, float(dy)));
}

/// The window's back buffer as an image (sRGB values, as displayed).
Image grabWindow(int width, int height) {
    std::vector<float> rgba(size_t(width) * height * 4);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rgba.data());
    Image img(width, height, {"R", "G", "B", "A"});
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            for (int c = 0; c < 4; ++c) img.at(x, y, c) = rgba[(size_t(height - 1 - y) * width + x) * 4 + c];
    return img;
}

struct GlfwSession {
    GlfwSession() {
        glfwSetErrorCallback([](int code, const char* text) { logVerbose("GLFW error ", code, ": ", text); });
        if (!glfwInit()) {
            const char* display = std::getenv("DISPLAY");
            throw Error(cat("hairpipe view needs a display: GLFW could not initialise (DISPLAY=",
                            display ? display : "unset", "); use `hairpipe render --preview` for headless frames"));
        }
    }
    ~GlfwSession() { glfwTerminate(); }
};

}  // namespace

void runViewer(const View& view, const PreviewSettings& settings, const ViewerFrameProvider& frames,
               const ViewerOptions& options) {
    if (options.frames.empty()) throw Error("hairpipe view: no frames to show");
    GlfwSession session;
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_DOUBLEBUFFER, GLFW_TRUE);
    GLFWwindow* window = glfwCreateWindow(options.width, options.height, "hairpipe view", nullptr, nullptr);
    if (!window) throw Error("hairpipe view: cannot open a window with OpenGL 4.5 core on this display");
    glfwMakeContextCurrent(window);
    glfwSwapInterval(options.exitAfter > 0 ? 0 : 1);

    ViewerState st;
    st.view = view;
    st.settings = settings;
    st.orbit = st.initialOrbit = Orbit::from(view.camera);
    st.playing = options.play;
    glfwSetWindowUserPointer(window, &st);
    glfwSetKeyCallback(window, onKey);
    glfwSetMouseButtonCallback(window, onButton);
    glfwSetCursorPosCallback(window, onCursor);
    glfwSetScrollCallback(window, onScroll);

    {
        PreviewRenderer renderer(settings);
        logInfo("hairpipe view: ", renderer.stats().renderer,
                " — space play/pause, arrows step, drag orbit, wheel zoom, V/M/B/S shadows, G fur, H head, Q quit");
        int shown = 0;
        auto last = std::chrono::steady_clock::now();
        double carried = 0.0;  // playback time not yet turned into frames
        while (!glfwWindowShouldClose(window)) {
            glfwPollEvents();
            if (st.settingsChanged) renderer.setSettings(st.settings), st.settingsChanged = false;
            const size_t count = options.frames.size();
            st.frameIndex = std::min(st.frameIndex, count - 1);
            const int frame = options.frames[st.frameIndex];

            int fw = 0, fh = 0;
            glfwGetFramebufferSize(window, &fw, &fh);
            if (fw < 1 || fh < 1) continue;
            st.view.camera.width = fw;
            st.view.camera.height = fh;
            st.view.camera.position = st.orbit.position(st.view.camera.target);
            const ViewerFrame data = frames(frame);
            PreviewFrame pf;
            pf.time = data.time;
            pf.strands = data.strands;
            pf.head = data.head;
            pf.headTransform = data.headTransform;
            const auto start = std::chrono::steady_clock::now();
            renderer.draw(st.view, pf);
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            renderer.present(0, 0, fw, fh);
            glFinish();
            const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
            ++shown;
            if (options.exitAfter > 0 && shown >= options.exitAfter) {
                if (!options.screenshot.empty()) writeImage(options.screenshot, grabWindow(fw, fh), {true, false, {}});
                glfwSetWindowShouldClose(window, GLFW_TRUE);
            }
            glfwSwapBuffers(window);
            glfwSetWindowTitle(window, cat("hairpipe view — frame ", frame, st.playing ? " (playing)" : " (paused)",
                                           " — ", int(ms), " ms — voxels ",
                                           st.settings.shadow.voxels ? voxelModeName(st.settings.shadow) : "off",
                                           st.settings.shadow.sumAlongLight ? "" : " (unsummed)", ", shadow map ",
                                           st.settings.shadow.shadowMap ? "on" : "off")
                                           .c_str());
            // Playback at the shot's rate, or one frame per draw when drawing is slower (or scripted).
            const auto now = std::chrono::steady_clock::now();
            carried += std::chrono::duration<double>(now - last).count() * options.fps;
            last = now;
            if (st.playing || options.exitAfter > 0) {
                const size_t step = options.exitAfter > 0 ? 1 : std::max<size_t>(1, size_t(carried));
                carried = std::max(0.0, carried - double(step));
                st.frameIndex = (st.frameIndex + step) % count;
            } else {
                carried = 0.0;
            }
        }
    }
    glfwDestroyWindow(window);
}

}  // namespace hp
