#include "core/window.hpp"

#include <SDL.h>
#include <SDL_opengl.h>
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

// Dear ImGui renamed the SDL2 backend header in 1.89; Debian 12 ships 1.86.
#if __has_include(<backends/imgui_impl_sdl2.h>)
#include <backends/imgui_impl_sdl2.h>
#else
#include <backends/imgui_impl_sdl.h>
#endif
#include <backends/imgui_impl_opengl3.h>

namespace boxes {
static_assert(kPanelFoldKey == SDLK_F1 && kPanelMoveKey == SDLK_F2, "the panel's keys");
namespace {

// Runs a cleanup action when the scope ends, also while an exception unwinds.
template <typename F>
class Defer {
public:
    explicit Defer(F action) : action_(std::move(action)) {}
    ~Defer() { action_(); }
    Defer(const Defer&) = delete;
    Defer& operator=(const Defer&) = delete;

private:
    F action_;
};

// Error messages must stay on one line: SDL and driver messages sometimes do not.
std::string oneLine(std::string text) {
    std::replace(text.begin(), text.end(), '\n', ' ');
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text;
}

std::runtime_error noWindow(const std::string& reason) {
    return std::runtime_error("cannot open a window (" + oneLine(reason) +
                              "); run with --headless");
}

// The few OpenGL functions this file calls, loaded through SDL so that the same code works
// with GLX and EGL (SDL_VIDEODRIVER=offscreen). ImGui's OpenGL backend loads its own copy.
#define BOXES_GL_FUNCTIONS(X)                                                       \
    X(void, ActiveTexture, (GLenum))                                                \
    X(void, AttachShader, (GLuint, GLuint))                                         \
    X(void, BindTexture, (GLenum, GLuint))                                          \
    X(void, BindVertexArray, (GLuint))                                              \
    X(void, Clear, (GLbitfield))                                                    \
    X(void, ClearColor, (GLfloat, GLfloat, GLfloat, GLfloat))                       \
    X(void, CompileShader, (GLuint))                                                \
    X(GLuint, CreateProgram, ())                                                    \
    X(GLuint, CreateShader, (GLenum))                                               \
    X(void, DeleteProgram, (GLuint))                                                \
    X(void, DeleteShader, (GLuint))                                                 \
    X(void, DeleteTextures, (GLsizei, const GLuint*))                               \
    X(void, DeleteVertexArrays, (GLsizei, const GLuint*))                           \
    X(void, Disable, (GLenum))                                                      \
    X(void, Finish, ())                                                             \
    X(void, DrawArrays, (GLenum, GLint, GLsizei))                                   \
    X(void, GenTextures, (GLsizei, GLuint*))                                        \
    X(void, GenVertexArrays, (GLsizei, GLuint*))                                    \
    X(void, GetProgramInfoLog, (GLuint, GLsizei, GLsizei*, GLchar*))                \
    X(void, GetProgramiv, (GLuint, GLenum, GLint*))                                 \
    X(void, GetShaderInfoLog, (GLuint, GLsizei, GLsizei*, GLchar*))                 \
    X(void, GetShaderiv, (GLuint, GLenum, GLint*))                                  \
    X(void, LinkProgram, (GLuint))                                                  \
    X(void, PixelStorei, (GLenum, GLint))                                           \
    X(void, ReadBuffer, (GLenum))                                                   \
    X(void, ReadPixels, (GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, void*))    \
    X(void, ShaderSource, (GLuint, GLsizei, const GLchar* const*, const GLint*))    \
    X(void, TexImage2D,                                                             \
      (GLenum, GLint, GLint, GLsizei, GLsizei, GLint, GLenum, GLenum, const void*)) \
    X(void, TexParameteri, (GLenum, GLenum, GLint))                                 \
    X(void, TexSubImage2D,                                                          \
      (GLenum, GLint, GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, const void*)) \
    X(void, UseProgram, (GLuint))                                                   \
    X(void, Viewport, (GLint, GLint, GLsizei, GLsizei))

struct Gl {
#define BOXES_GL_MEMBER(ret, name, args) ret(APIENTRYP name) args = nullptr;
    BOXES_GL_FUNCTIONS(BOXES_GL_MEMBER)
#undef BOXES_GL_MEMBER

    // Returns the name of the first function the driver does not provide, or nullptr.
    const char* load() {
#define BOXES_GL_LOAD(ret, name, args)                                          \
    name = reinterpret_cast<decltype(name)>(SDL_GL_GetProcAddress("gl" #name)); \
    if (!name) return "gl" #name;
        BOXES_GL_FUNCTIONS(BOXES_GL_LOAD)
#undef BOXES_GL_LOAD
        return nullptr;
    }
};

// A quad generated from gl_VertexID (no vertex buffer). The image is uploaded as linear
// floats and sRGB-encoded here, like Image::toRgb8() (clamp to [0,1], NaN to black), so
// the window looks like the PNG without a slow per-pixel conversion on the CPU each frame.
constexpr const char* kVertexShader = R"(#version 330 core
out vec2 uv;
void main() {
    vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1));
    uv = vec2(corner.x, 1.0 - corner.y);  // image row 0 is at the top
    gl_Position = vec4(2.0 * corner - 1.0, 0.0, 1.0);
}
)";

constexpr const char* kFragmentShader = R"(#version 330 core
uniform sampler2D image;
in vec2 uv;
out vec4 color;
float encodeSrgb(float c) {
    if (isnan(c)) return 0.0;
    c = clamp(c, 0.0, 1.0);
    return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}
void main() {
    vec3 c = texture(image, uv).rgb;
    color = vec4(encodeSrgb(c.r), encodeSrgb(c.g), encodeSrgb(c.b), 1.0);
}
)";

// The GL objects that draw the step's image letterboxed into the window.
class ImageView {
public:
    explicit ImageView(const Gl& gl) : gl_(gl) {
        program_ = gl_.CreateProgram();
        GLuint vertex = compile(GL_VERTEX_SHADER, kVertexShader);
        GLuint fragment = compile(GL_FRAGMENT_SHADER, kFragmentShader);
        gl_.AttachShader(program_, vertex);
        gl_.AttachShader(program_, fragment);
        gl_.LinkProgram(program_);
        gl_.DeleteShader(vertex);  // only flagged for deletion while attached
        gl_.DeleteShader(fragment);
        GLint linked = GL_FALSE;
        gl_.GetProgramiv(program_, GL_LINK_STATUS, &linked);
        if (linked != GL_TRUE) {
            char log[512] = {};
            gl_.GetProgramInfoLog(program_, sizeof(log), nullptr, log);
            release();
            throw noWindow(std::string("OpenGL shader link failed: ") + log);
        }
        gl_.GenVertexArrays(1, &vertexArray_);  // the core profile draws nothing without one
        gl_.GenTextures(1, &texture_);
        gl_.BindTexture(GL_TEXTURE_2D, texture_);
        // GL_NEAREST keeps the pixels of a small image visible as squares.
        gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    ~ImageView() { release(); }
    ImageView(const ImageView&) = delete;
    ImageView& operator=(const ImageView&) = delete;

    // Uploads the image (every frame: the step may have changed it in place) and draws it
    // as large as fits into the area (framebuffer pixels, from the bottom-left corner, as
    // OpenGL counts), centred, keeping its aspect ratio.
    void draw(const Image& image, int areaX, int areaY, int areaWidth, int areaHeight) {
        static_assert(sizeof(Vec3) == 3 * sizeof(float), "Image pixels must be packed floats");
        if (image.empty() || areaWidth <= 0 || areaHeight <= 0) return;
        int w = image.width(), h = image.height();
        gl_.ActiveTexture(GL_TEXTURE0);
        gl_.BindTexture(GL_TEXTURE_2D, texture_);
        gl_.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
        gl_.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);  // ImGui's backend may have changed it
        if (w != textureWidth_ || h != textureHeight_) {
            gl_.TexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, w, h, 0, GL_RGB, GL_FLOAT,
                           image.pixels().data());
            textureWidth_ = w;
            textureHeight_ = h;
        } else {
            gl_.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGB, GL_FLOAT,
                              image.pixels().data());
        }

        double scale = std::min(double(areaWidth) / w, double(areaHeight) / h);
        int quadWidth = std::max(1, int(std::lround(w * scale)));
        int quadHeight = std::max(1, int(std::lround(h * scale)));
        gl_.Viewport(areaX + (areaWidth - quadWidth) / 2, areaY + (areaHeight - quadHeight) / 2,
                     quadWidth, quadHeight);
        gl_.Disable(GL_BLEND);
        gl_.Disable(GL_SCISSOR_TEST);
        gl_.Disable(GL_DEPTH_TEST);
        gl_.Disable(GL_CULL_FACE);
        gl_.UseProgram(program_);
        gl_.BindVertexArray(vertexArray_);
        gl_.DrawArrays(GL_TRIANGLE_STRIP, 0, 4);
        gl_.BindVertexArray(0);
        gl_.UseProgram(0);
    }

private:
    GLuint compile(GLenum type, const char* source) {
        GLuint shader = gl_.CreateShader(type);
        gl_.ShaderSource(shader, 1, &source, nullptr);
        gl_.CompileShader(shader);
        GLint compiled = GL_FALSE;
        gl_.GetShaderiv(shader, GL_COMPILE_STATUS, &compiled);
        if (compiled != GL_TRUE) {
            char log[512] = {};
            gl_.GetShaderInfoLog(shader, sizeof(log), nullptr, log);
            gl_.DeleteShader(shader);
            release();
            throw noWindow(std::string("OpenGL shader compile failed: ") + log);
        }
        return shader;
    }

    void release() {
        if (texture_) gl_.DeleteTextures(1, &texture_);
        if (vertexArray_) gl_.DeleteVertexArrays(1, &vertexArray_);
        if (program_) gl_.DeleteProgram(program_);
        texture_ = vertexArray_ = program_ = 0;
    }

    const Gl& gl_;
    GLuint program_ = 0;
    GLuint vertexArray_ = 0;
    GLuint texture_ = 0;
    int textureWidth_ = 0;
    int textureHeight_ = 0;
};

// True when SDL_VIDEODRIVER (a hint or the environment variable, possibly a comma-separated
// list) names this driver.
bool videoDriverRequested(const char* driver) {
    const char* hint = SDL_GetHint(SDL_HINT_VIDEODRIVER);
    if (!hint) return false;
    std::string list = hint;
    size_t start = 0;
    while (start <= list.size()) {
        size_t end = std::min(list.find(',', start), list.size());
        if (SDL_strcasecmp(list.substr(start, end - start).c_str(), driver) == 0) return true;
        start = end + 1;
    }
    return false;
}

// Reads the back buffer (before the swap, when its content is defined) into a PNG.
void writeScreenshot(const Gl& gl, int width, int height, const std::string& path) {
    std::vector<uint8_t> rows(size_t(width) * size_t(height) * 3);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadBuffer(GL_BACK);
    gl.ReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
    // OpenGL's row 0 is the bottom one; a PNG starts at the top.
    size_t stride = size_t(width) * 3;
    std::vector<uint8_t> flipped(rows.size());
    for (int y = 0; y < height; ++y)
        std::copy_n(rows.data() + size_t(height - 1 - y) * stride, stride,
                    flipped.data() + size_t(y) * stride);
    // fromRgb8 decodes sRGB and writePng encodes it again: exact for every 8-bit value.
    Image::fromRgb8(width, height, flipped.data()).writePng(path);
}

// What the panel takes from the window, in framebuffer pixels: a column on the right, or a
// line at the top; the picture is drawn in the rest.
struct PanelArea {
    int right = 0, top = 0;
};

// The panel: the step's keys and the window's own, the frame time, a render's progress and
// the step's lines; beside the picture by default, or over it, or folded to one line.
PanelArea drawPanel(const WindowOptions& options, const PanelPlacement& placement,
                    WindowCallbacks& callbacks, const Image& image, double frameSeconds) {
    const ImGuiIO& io = ImGui::GetIO();
    const float toPixels = io.DisplayFramebufferScale.x;
    std::pair<double, std::string> progress{-1.0, ""};
    if (callbacks.progress) progress = callbacks.progress();
    ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoSavedSettings |
                             ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoFocusOnAppearing |
                             ImGuiWindowFlags_NoNav;
    PanelArea area;
    if (placement.folded) {
        // One line: what the window is, how to unfold the panel, and a render's progress.
        const float height = ImGui::GetFrameHeightWithSpacing();
        ImGui::SetNextWindowPos(ImVec2(0.0f, 0.0f), ImGuiCond_Always);
        if (placement.beside) {
            ImGui::SetNextWindowSize(ImVec2(io.DisplaySize.x, height), ImGuiCond_Always);
            area.top = int(std::ceil(height * toPixels));
        } else {
            flags |= ImGuiWindowFlags_AlwaysAutoResize;
            ImGui::SetNextWindowBgAlpha(0.65f);
        }
        ImGui::Begin("##boxes_panel", nullptr, flags);
        ImGui::Text("%s  |  F1 keys and status  |  %.1f ms/frame", options.title.c_str(),
                    frameSeconds * 1000.0);
        if (progress.first >= 0.0) {
            ImGui::SameLine();
            ImGui::Text("|  %s %3.0f%%", progress.second.c_str(), 100.0 * progress.first);
        }
        ImGui::End();
        return area;
    }
    if (placement.beside) {  // a column on the right, the full height
        const float width = std::clamp(0.3f * io.DisplaySize.x, 250.0f, 380.0f);
        ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - width, 0.0f), ImGuiCond_Always);
        ImGui::SetNextWindowSize(ImVec2(width, io.DisplaySize.y), ImGuiCond_Always);
        area.right = int(std::ceil(width * toPixels));
    } else {
        ImGui::SetNextWindowPos(ImVec2(10.0f, 10.0f), ImGuiCond_Always);
        ImGui::SetNextWindowBgAlpha(0.65f);
        flags |= ImGuiWindowFlags_AlwaysAutoResize;
    }
    ImGui::Begin("##boxes_panel", nullptr, flags);
    if (placement.beside) ImGui::PushTextWrapPos(0.0f);  // long lines wrap in the column
    ImGui::TextUnformatted(options.title.c_str());
    ImGui::Text("%.1f ms/frame", frameSeconds * 1000.0);
    if (image.empty())
        ImGui::TextUnformatted("no image");
    else
        ImGui::Text("image %d x %d", image.width(), image.height());
    if (progress.first >= 0.0)
        ImGui::ProgressBar(float(progress.first), ImVec2(-1.0f, 0.0f), progress.second.c_str());
    ImGui::Separator();

    // SDL_GetKeyName may reuse one buffer between calls, so copy each name.
    std::vector<std::pair<std::string, std::string>> lines;
    for (const KeyBinding& binding : callbacks.keys) {
        std::string name = SDL_GetKeyName(binding.key);
        lines.emplace_back(name.empty() ? "?" : name, binding.description);
    }
    lines.emplace_back("F1", "panel: fold to one line");
    lines.emplace_back("F2",
                       placement.beside ? "panel: over the picture" : "panel: beside the picture");
    lines.emplace_back("Esc/Q", "quit");
    float column = 0.0f;
    for (const auto& line : lines)
        column = std::max(column, ImGui::CalcTextSize(line.first.c_str()).x);
    column += 2.0f * ImGui::GetStyle().ItemSpacing.x;
    for (const auto& line : lines) {
        ImGui::TextUnformatted(line.first.c_str());
        ImGui::SameLine(ImGui::GetCursorPosX() + column);
        ImGui::TextUnformatted(line.second.c_str());
    }

    if (callbacks.panel) {
        ImGui::Separator();
        callbacks.panel();
    }
    if (placement.beside) ImGui::PopTextWrapPos();
    ImGui::End();
    return area;
}

// BOXES_WINDOW_LOG=FILE: what the window did and when, in milliseconds since it was
// created, last on each line: "frame N PROGRESS T", "key NAME T", "quit N T", for the test that
// checks the first frame comes at once and Escape within a frame (tests/windows_x11.py).
class WindowLog {
public:
    WindowLog() {
        const char* path = std::getenv("BOXES_WINDOW_LOG");
        if (path && *path) file_ = std::fopen(path, "w");
    }
    ~WindowLog() {
        if (file_) std::fclose(file_);
    }
    WindowLog(const WindowLog&) = delete;
    WindowLog& operator=(const WindowLog&) = delete;
    void start() { start_ = SDL_GetPerformanceCounter(); }
    template <typename... Args>
    void line(const char* format, Args... args) {
        if (!file_) return;
        double ms = 1000.0 * double(SDL_GetPerformanceCounter() - start_) /
                    double(SDL_GetPerformanceFrequency());
        std::fprintf(file_, format, args..., ms);
        std::fputc('\n', file_);
        std::fflush(file_);
    }

private:
    std::FILE* file_ = nullptr;
    Uint64 start_ = 0;
};

// Queues a key press and release like the keyboard would, so scripted keys take the
// same path as real ones (ImGui first, then onKey and the Escape/Q check).
void pushKey(SDL_Window* window, SDL_Keycode key) {
    for (Uint32 type : {Uint32(SDL_KEYDOWN), Uint32(SDL_KEYUP)}) {
        SDL_Event event{};
        event.type = type;
        event.key.timestamp = SDL_GetTicks();
        event.key.windowID = SDL_GetWindowID(window);
        event.key.state = type == SDL_KEYDOWN ? SDL_PRESSED : SDL_RELEASED;
        event.key.keysym.sym = key;
        event.key.keysym.scancode = SDL_GetScancodeFromKey(key);
        if (SDL_PushEvent(&event) < 0)
            throw std::runtime_error("cannot queue a scripted key: " + oneLine(SDL_GetError()));
    }
}

}  // namespace

void runWindow(const WindowOptions& options, WindowCallbacks& callbacks) {
    if (!callbacks.frame) throw std::invalid_argument("runWindow: callbacks.frame is not set");

    // SDL_Quit is safe (and needed to undo partial work) even when SDL_Init fails.
    Defer quitSdl([] { SDL_Quit(); });
    if (SDL_Init(SDL_INIT_VIDEO) != 0) throw noWindow(std::string("SDL: ") + SDL_GetError());
    // Without a display SDL 2.26 falls back to its invisible offscreen driver: use that only
    // when asked for (CI), or a user would wait for a window that never shows up.
    const char* driver = SDL_GetCurrentVideoDriver();
    if (driver && SDL_strcasecmp(driver, "offscreen") == 0 && !videoDriverRequested(driver))
        throw noWindow("no display found; SDL_VIDEODRIVER=offscreen renders without one");

    std::vector<SDL_Keycode> scriptedKeys;
    for (const std::string& name : options.scriptedKeys) {
        SDL_Keycode key = SDL_GetKeyFromName(name.c_str());
        if (key == SDLK_UNKNOWN) throw std::runtime_error("unknown key name '" + name + "'");
        scriptedKeys.push_back(key);
    }
    const bool scripted = options.scriptedFrames > 0;

    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MAJOR_VERSION, 3);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MINOR_VERSION, 3);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_PROFILE_MASK, SDL_GL_CONTEXT_PROFILE_CORE);
#ifdef __APPLE__
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_FLAGS, SDL_GL_CONTEXT_FORWARD_COMPATIBLE_FLAG);
#endif
    SDL_GL_SetAttribute(SDL_GL_DOUBLEBUFFER, 1);
    SDL_GL_SetAttribute(SDL_GL_RED_SIZE, 8);
    SDL_GL_SetAttribute(SDL_GL_GREEN_SIZE, 8);
    SDL_GL_SetAttribute(SDL_GL_BLUE_SIZE, 8);

    WindowLog log;
    SDL_Window* window = SDL_CreateWindow(
        options.title.c_str(), SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED, options.width,
        options.height,
        // Hidden until its first frame is ready (below): a student never sees it black.
        SDL_WINDOW_OPENGL | SDL_WINDOW_RESIZABLE | SDL_WINDOW_ALLOW_HIGHDPI | SDL_WINDOW_HIDDEN);
    if (!window) throw noWindow(std::string("SDL: ") + SDL_GetError());
    Defer destroyWindow([window] { SDL_DestroyWindow(window); });

    SDL_GLContext context = SDL_GL_CreateContext(window);
    if (!context) throw noWindow(std::string("no OpenGL 3.3 core context: ") + SDL_GetError());
    Defer deleteContext([context] { SDL_GL_DeleteContext(context); });
    if (SDL_GL_MakeCurrent(window, context) != 0)
        throw noWindow(std::string("SDL_GL_MakeCurrent: ") + SDL_GetError());
    // Scripted runs go as fast as they can; interactive ones wait for vsync (if available).
    SDL_GL_SetSwapInterval(scripted ? 0 : 1);

    Gl gl;
    if (const char* missing = gl.load())
        throw noWindow(std::string("OpenGL function ") + missing + " is missing");
    ImageView view(gl);

    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    Defer destroyImGui([] { ImGui::DestroyContext(); });
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;  // no imgui.ini next to the program
    io.LogFilename = nullptr;
    ImGui::StyleColorsDark();
    if (!ImGui_ImplSDL2_InitForOpenGL(window, context))
        throw noWindow("Dear ImGui's SDL2 backend failed to initialise");
    Defer shutdownImGuiSdl([] { ImGui_ImplSDL2_Shutdown(); });
    if (!ImGui_ImplOpenGL3_Init("#version 330 core"))
        throw noWindow("Dear ImGui's OpenGL 3 backend failed to initialise");
    Defer shutdownImGuiGl([] { ImGui_ImplOpenGL3_Shutdown(); });

    // The first use of each shader and of the panel's font costs a lot (a software OpenGL
    // compiles them then): done once while the window is hidden, so that once shown it
    // draws its first frame at once.
    {
        PanelPlacement placement = options.panel;
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplSDL2_NewFrame();
        ImGui::NewFrame();
        Image warmUp(1, 1);
        drawPanel(options, placement, callbacks, warmUp, 0.0);
        ImGui::Render();
        view.draw(warmUp, 0, 0, 1, 1);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
        gl.Finish();
    }
    SDL_ShowWindow(window);
    log.start();

    // F1 and F2 place the panel; Escape and Q quit unless the step used the key (e.g. to
    // cancel something).
    PanelPlacement placement = options.panel;
    auto pressKey = [&](SDL_Keycode key) {
        if (key == kPanelFoldKey || key == kPanelMoveKey) {
            (key == kPanelFoldKey ? placement.folded : placement.beside) ^= true;
            return false;
        }
        bool used = callbacks.onKey ? callbacks.onKey(int(key)) : false;
        // A key the window lists must do something: scripted runs (the tests) say so.
        bool listed = std::any_of(callbacks.keys.begin(), callbacks.keys.end(),
                                  [&](const KeyBinding& b) { return b.key == key; });
        if (scripted && listed && !used)
            throw std::logic_error(std::string("the window lists key '") + SDL_GetKeyName(key) +
                                   "' but it did nothing");
        return !used && (key == SDLK_ESCAPE || key == SDLK_q);
    };

    const Uint64 ticksPerSecond = SDL_GetPerformanceFrequency();
    Uint64 previousTicks = SDL_GetPerformanceCounter();
    double smoothedFrameSeconds = 0.0;
    bool quit = false;
    for (int frameIndex = 0; !quit; ++frameIndex) {
        // scriptedKeys[i] is pressed before frame i + 1, so frame 0 shows the start state.
        if (scripted && frameIndex > 0 && size_t(frameIndex - 1) < scriptedKeys.size())
            pushKey(window, scriptedKeys[size_t(frameIndex - 1)]);

        SDL_Event event;
        while (SDL_PollEvent(&event)) {
            ImGui_ImplSDL2_ProcessEvent(&event);
            switch (event.type) {
                case SDL_QUIT:
                    quit = true;
                    break;
                case SDL_WINDOWEVENT:
                    if (event.window.event == SDL_WINDOWEVENT_CLOSE) quit = true;
                    break;
                case SDL_KEYDOWN:
                    // Typing into an ImGui widget must not trigger the step's keys.
                    log.line("key %s %.2f", SDL_GetKeyName(event.key.keysym.sym));
                    if (!io.WantCaptureKeyboard && pressKey(event.key.keysym.sym)) quit = true;
                    break;
                case SDL_MOUSEMOTION:
                    if (event.motion.state != 0 && !io.WantCaptureMouse && callbacks.onMouseDrag)
                        callbacks.onMouseDrag(float(event.motion.xrel), float(event.motion.yrel));
                    break;
                default:
                    break;
            }
        }
        if (quit) log.line("quit %d %.2f", frameIndex);
        const bool lastFrame = quit || (scripted && frameIndex + 1 >= options.scriptedFrames);
        // Closing draws one more frame only when it is needed for the screenshot.
        if (quit && options.screenshotPath.empty()) break;

        if (!scripted && (SDL_GetWindowFlags(window) & SDL_WINDOW_MINIMIZED)) {
            SDL_Delay(50);  // nothing to show; do not spin (swaps may not block)
            continue;
        }

        Uint64 ticks = SDL_GetPerformanceCounter();
        double elapsed = double(ticks - previousTicks) / double(ticksPerSecond);
        previousTicks = ticks;
        if (frameIndex > 0)
            smoothedFrameSeconds =
                smoothedFrameSeconds == 0.0 ? elapsed : 0.9 * smoothedFrameSeconds + 0.1 * elapsed;
        // Scripted runs use a fixed step so their output does not depend on the machine.
        double dt = frameIndex == 0 ? 0.0 : scripted ? 1.0 / 60.0 : elapsed;
        const Image& image = callbacks.frame(dt);

        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplSDL2_NewFrame();
        ImGui::NewFrame();
        PanelArea panel = drawPanel(options, placement, callbacks, image, smoothedFrameSeconds);
        ImGui::Render();

        int framebufferWidth = 0, framebufferHeight = 0;
        SDL_GL_GetDrawableSize(window, &framebufferWidth, &framebufferHeight);
        gl.Viewport(0, 0, framebufferWidth, framebufferHeight);
        gl.ClearColor(0.08f, 0.08f, 0.08f, 1.0f);
        gl.Clear(GL_COLOR_BUFFER_BIT);
        // The picture in what the panel leaves of the window (OpenGL counts rows from the
        // bottom, so a line at the top shortens the area without moving its origin).
        view.draw(image, 0, 0, framebufferWidth - panel.right, framebufferHeight - panel.top);
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

        if (lastFrame && !options.screenshotPath.empty() && framebufferWidth > 0 &&
            framebufferHeight > 0)
            writeScreenshot(gl, framebufferWidth, framebufferHeight, options.screenshotPath);
        SDL_GL_SwapWindow(window);
        log.line("frame %d %.3f %.2f", frameIndex,
                 callbacks.progress ? callbacks.progress().first : -1.0);
        if (lastFrame) break;
    }
    if (callbacks.onClose) callbacks.onClose();
    log.line("closed %.2f");
}

}  // namespace boxes
