// raster_gl: the bench's rasterizer row. One view drawn by step 06 and by OpenGL on Mesa's
// llvmpipe (the same GL the windows get: SDL's offscreen driver, EGL, with
// LIBGL_ALWAYS_SOFTWARE=1, GALLIUM_DRIVER=llvmpipe and LP_NUM_THREADS=1 unless set), the same
// triangles, camera, clip planes and size, visibility only and shaded, in paired rounds in
// one process. Prints one JSON line: per variant the median frame time (wall and process CPU)
// of each round, the rounds' ratios, and the share of covered pixels where both name the
// same triangle.
//
//   raster_gl --scene bunny|FILE.obj [--inside] [--width W] [--height H] [--repeat K]
//             [--rounds R] [--data DIR]
#include <SDL.h>
#include <SDL_opengl.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "06_raster/compare.hpp"
#include "06_raster/frame.hpp"
#include "06_raster/raster.hpp"
#include "core/timing.hpp"

#ifndef BOXES_DATA_DIR
#define BOXES_DATA_DIR "data"
#endif

namespace {

using namespace boxes;

double processCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// The GL 3.3 core functions this harness calls, loaded through SDL as core/window.cpp does.
// A loader of its own, not the window's: each lists the functions it calls (this one
// buffers, framebuffers, uniforms and the depth test; the window a textured quad), and the
// bench's harness stays out of the core.
#define RASTER_GL_FUNCTIONS(X)                                                             \
    X(void, AttachShader, (GLuint, GLuint))                                                \
    X(void, BindBuffer, (GLenum, GLuint))                                                  \
    X(void, BindFramebuffer, (GLenum, GLuint))                                             \
    X(void, BindTexture, (GLenum, GLuint))                                                 \
    X(void, BindVertexArray, (GLuint))                                                     \
    X(void, BufferData, (GLenum, GLsizeiptr, const void*, GLenum))                         \
    X(void, ClipControl, (GLenum, GLenum))                                                 \
    X(GLenum, CheckFramebufferStatus, (GLenum))                                            \
    X(void, ClearBufferfv, (GLenum, GLint, const GLfloat*))                                \
    X(void, ClearBufferuiv, (GLenum, GLint, const GLuint*))                                \
    X(void, CompileShader, (GLuint))                                                       \
    X(GLuint, CreateProgram, ())                                                           \
    X(GLuint, CreateShader, (GLenum))                                                      \
    X(void, DeleteShader, (GLuint))                                                        \
    X(void, DepthFunc, (GLenum))                                                           \
    X(void, Disable, (GLenum))                                                             \
    X(void, DrawBuffers, (GLsizei, const GLenum*))                                         \
    X(void, DrawElements, (GLenum, GLsizei, GLenum, const void*))                          \
    X(void, Enable, (GLenum))                                                              \
    X(void, EnableVertexAttribArray, (GLuint))                                             \
    X(void, Finish, ())                                                                    \
    X(void, FramebufferTexture2D, (GLenum, GLenum, GLenum, GLuint, GLint))                 \
    X(void, GenBuffers, (GLsizei, GLuint*))                                                \
    X(void, GenFramebuffers, (GLsizei, GLuint*))                                           \
    X(void, GenTextures, (GLsizei, GLuint*))                                               \
    X(void, GenVertexArrays, (GLsizei, GLuint*))                                           \
    X(GLenum, GetError, ())                                                                \
    X(void, GetProgramInfoLog, (GLuint, GLsizei, GLsizei*, GLchar*))                       \
    X(void, GetProgramiv, (GLuint, GLenum, GLint*))                                        \
    X(void, GetShaderInfoLog, (GLuint, GLsizei, GLsizei*, GLchar*))                        \
    X(void, GetShaderiv, (GLuint, GLenum, GLint*))                                         \
    X(const GLubyte*, GetString, (GLenum))                                                 \
    X(GLint, GetUniformLocation, (GLuint, const GLchar*))                                  \
    X(void, LinkProgram, (GLuint))                                                         \
    X(void, PixelStorei, (GLenum, GLint))                                                  \
    X(void, ReadBuffer, (GLenum))                                                          \
    X(void, ReadPixels, (GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, void*))           \
    X(void, ShaderSource, (GLuint, GLsizei, const GLchar* const*, const GLint*))           \
    X(void, TexImage2D,                                                                    \
      (GLenum, GLint, GLint, GLsizei, GLsizei, GLint, GLenum, GLenum, const void*))        \
    X(void, TexParameteri, (GLenum, GLenum, GLint))                                        \
    X(void, Uniform1i, (GLint, GLint))                                                     \
    X(void, Uniform3fv, (GLint, GLsizei, const GLfloat*))                                  \
    X(void, Uniform1fv, (GLint, GLsizei, const GLfloat*))                                  \
    X(void, UniformMatrix4fv, (GLint, GLsizei, GLboolean, const GLfloat*))                 \
    X(void, UseProgram, (GLuint))                                                          \
    X(void, VertexAttribPointer, (GLuint, GLint, GLenum, GLboolean, GLsizei, const void*)) \
    X(void, Viewport, (GLint, GLint, GLsizei, GLsizei))

struct Gl {
#define RASTER_GL_MEMBER(ret, name, args) ret(APIENTRYP name) args = nullptr;
    RASTER_GL_FUNCTIONS(RASTER_GL_MEMBER)
#undef RASTER_GL_MEMBER
    void load() {
#define RASTER_GL_LOAD(ret, name, args)                                         \
    name = reinterpret_cast<decltype(name)>(SDL_GL_GetProcAddress("gl" #name)); \
    if (!name) throw std::runtime_error("the GL driver has no gl" #name);
        RASTER_GL_FUNCTIONS(RASTER_GL_LOAD)
#undef RASTER_GL_LOAD
    }
};

constexpr int kMaxLights = 8;

// Both passes write the triangle (gl_PrimitiveID: the index in the draw, the raster scene's
// triangle index) and test depth; the shaded pass also writes the colour: step 06's
// shadeFrame without shadows (ambient plus each point light's albedo * I * cos / d^2, the
// normals turned to face the eye).
constexpr const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 albedo;
uniform mat4 viewProjection;
out vec3 worldPosition;
out vec3 worldNormal;
out vec3 surfaceAlbedo;
void main() {
    worldPosition = position;
    worldNormal = normal;
    surfaceAlbedo = albedo;
    gl_Position = viewProjection * vec4(position, 1.0);
}
)";

constexpr const char* kVisibilityShader = R"(#version 330 core
layout(location = 0) out uint triangle;
void main() { triangle = uint(gl_PrimitiveID); }
)";

constexpr const char* kShadedShader = R"(#version 330 core
#define MAX_LIGHTS 8
in vec3 worldPosition;
in vec3 worldNormal;
in vec3 surfaceAlbedo;
uniform vec3 eye;
uniform vec3 ambient;
uniform int lightCount;
uniform vec3 lightPosition[MAX_LIGHTS];
uniform vec3 lightIntensity[MAX_LIGHTS];
uniform float lightRadius[MAX_LIGHTS];
layout(location = 0) out uint triangle;
layout(location = 1) out vec4 colour;
void main() {
    triangle = uint(gl_PrimitiveID);
    vec3 ng = normalize(cross(dFdx(worldPosition), dFdy(worldPosition)));
    if (dot(ng, eye - worldPosition) < 0.0) ng = -ng;
    vec3 n = normalize(worldNormal);
    if (dot(n, ng) < 0.0) n = -n;
    vec3 c = ambient * surfaceAlbedo;
    for (int l = 0; l < lightCount; ++l) {
        vec3 toLight = lightPosition[l] - worldPosition;
        float dist2 = dot(toLight, toLight);
        float cosine = dot(n, toLight);
        if (dist2 <= lightRadius[l] * lightRadius[l] && cosine > 0.0 && dot(ng, toLight) > 0.0)
            c += surfaceAlbedo * lightIntensity[l] * (cosine / (dist2 * sqrt(dist2)));
    }
    colour = vec4(c, 1.0);
}
)";

// An offscreen GL 3.3 core context (SDL's offscreen driver: EGL on Mesa) with the scene's
// triangles uploaded once and a framebuffer of the image's size.
class GlRaster {
public:
    GlRaster(const Scene& scene, const RasterScene& raster, int width, int height)
        : width_(width), height_(height) {
        if (SDL_Init(SDL_INIT_VIDEO) != 0)
            throw std::runtime_error(std::string("SDL_Init: ") + SDL_GetError());
        // 4.5 for glClipControl (reversed depth, below)
        SDL_GL_SetAttribute(SDL_GL_CONTEXT_MAJOR_VERSION, 4);
        SDL_GL_SetAttribute(SDL_GL_CONTEXT_MINOR_VERSION, 5);
        SDL_GL_SetAttribute(SDL_GL_CONTEXT_PROFILE_MASK, SDL_GL_CONTEXT_PROFILE_CORE);
        window_ =
            SDL_CreateWindow("raster_gl", 0, 0, 16, 16, SDL_WINDOW_OPENGL | SDL_WINDOW_HIDDEN);
        if (!window_) throw std::runtime_error(std::string("SDL_CreateWindow: ") + SDL_GetError());
        context_ = SDL_GL_CreateContext(window_);
        if (!context_)
            throw std::runtime_error(std::string("SDL_GL_CreateContext: ") + SDL_GetError());
        gl.load();
        renderer = reinterpret_cast<const char*>(gl.GetString(GL_RENDERER));
        visibility_ = program(kVisibilityShader);
        shaded_ = program(kShadedShader);
        upload(scene, raster);
        framebuffer();
    }
    ~GlRaster() {
        if (context_) SDL_GL_DeleteContext(context_);
        if (window_) SDL_DestroyWindow(window_);
        SDL_Quit();
    }
    GlRaster(const GlRaster&) = delete;
    GlRaster& operator=(const GlRaster&) = delete;

    // Step 06's projection, but with depth near/d in [0, 1] and the test "greater" (reversed
    // float depth, Reed 2015): with near at 1e-5 of the scene's size the usual mapping leaves
    // a float depth buffer no precision beyond the first units (step 06 stores d itself).
    // No far plane: step 06's lies beyond the scene, so it cuts nothing either.
    void setView(const Scene& scene, const Camera& camera, double near, double far) {
        Mat4d projection = projectionMatrix(camera, near, far);
        projection[0][2] = projection[1][2] = projection[2][2] = 0.0;
        projection[3][2] = near;
        const Mat4d vp = projection * viewMatrix(camera);
        float m[16];
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m[4 * c + r] = float(vp[c][r]);
        near_ = near;
        for (GLuint p : {visibility_, shaded_}) {
            gl.UseProgram(p);
            gl.UniformMatrix4fv(gl.GetUniformLocation(p, "viewProjection"), 1, GL_FALSE, m);
        }
        gl.UseProgram(shaded_);
        gl.Uniform3fv(gl.GetUniformLocation(shaded_, "eye"), 1, &camera.eye.x);
        gl.Uniform3fv(gl.GetUniformLocation(shaded_, "ambient"), 1, &scene.ambient.x);
        int count = int(std::min<size_t>(scene.lights.size(), kMaxLights));
        std::vector<float> pos, intensity, radius;
        for (int l = 0; l < count; ++l) {
            const PointLight& light = scene.lights[size_t(l)];
            pos.insert(pos.end(), {light.position.x, light.position.y, light.position.z});
            intensity.insert(intensity.end(),
                             {light.intensity.x, light.intensity.y, light.intensity.z});
            radius.push_back(std::min(light.radius, 3e18f));  // a finite square in the shader
        }
        gl.Uniform1i(gl.GetUniformLocation(shaded_, "lightCount"), count);
        if (count) {
            gl.Uniform3fv(gl.GetUniformLocation(shaded_, "lightPosition"), count, pos.data());
            gl.Uniform3fv(gl.GetUniformLocation(shaded_, "lightIntensity"), count,
                          intensity.data());
            gl.Uniform1fv(gl.GetUniformLocation(shaded_, "lightRadius"), count, radius.data());
        }
        background_ = scene.background;
        check("setting the view");
    }

    enum class Pass { DepthOnly, Visibility, Shaded };
    // One frame, finished (glFinish: the driver's rasterizer thread is done). DepthOnly: no
    // colour buffer (what the triangle output costs beside the depth test).
    void draw(Pass pass) {
        const bool shaded = pass == Pass::Shaded;
        const GLenum buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1}, none1 = GL_NONE;
        if (pass == Pass::DepthOnly)
            gl.DrawBuffers(1, &none1);
        else
            gl.DrawBuffers(shaded ? 2 : 1, buffers);
        const GLuint none[4] = {kNoPrimitive, 0, 0, 0};
        const GLfloat zero = 0.0f, bg[4] = {background_.x, background_.y, background_.z, 1.0f};
        if (pass != Pass::DepthOnly) gl.ClearBufferuiv(GL_COLOR, 0, none);
        if (shaded) gl.ClearBufferfv(GL_COLOR, 1, bg);
        gl.ClearBufferfv(GL_DEPTH, 0, &zero);
        gl.UseProgram(shaded ? shaded_ : visibility_);
        gl.DrawElements(GL_TRIANGLES, indexCount_, GL_UNSIGNED_INT, nullptr);
        gl.Finish();
    }

    // The last frame's triangle per pixel and depth along the view, row 0 at the top (GL's
    // row 0 is the bottom one; its pixel centres are step 06's, mirrored).
    void read(std::vector<uint32_t>& ids, std::vector<float>& depth) {
        const size_t n = size_t(width_) * size_t(height_);
        std::vector<uint32_t> rawIds(n);
        std::vector<float> rawDepth(n);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
        gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
        gl.ReadPixels(0, 0, width_, height_, GL_RED_INTEGER, GL_UNSIGNED_INT, rawIds.data());
        gl.ReadPixels(0, 0, width_, height_, GL_DEPTH_COMPONENT, GL_FLOAT, rawDepth.data());
        check("reading the frame back");
        ids.resize(n);
        depth.resize(n);
        for (int y = 0; y < height_; ++y)
            for (int x = 0; x < width_; ++x) {
                size_t from = size_t(height_ - 1 - y) * size_t(width_) + size_t(x);
                size_t to = size_t(y) * size_t(width_) + size_t(x);
                ids[to] = rawIds[from];
                // near/d back to the distance along the view
                depth[to] = rawIds[from] == kNoPrimitive ? kInfinity<float>
                                                         : float(near_ / double(rawDepth[from]));
            }
    }

    Gl gl;
    std::string renderer;

private:
    void check(const char* what) {
        GLenum e = gl.GetError();
        if (e != GL_NO_ERROR)
            throw std::runtime_error(std::string("GL error ") + std::to_string(e) + " " + what);
    }
    GLuint shader(GLenum kind, const char* source) {
        GLuint s = gl.CreateShader(kind);
        gl.ShaderSource(s, 1, &source, nullptr);
        gl.CompileShader(s);
        GLint ok = GL_FALSE;
        gl.GetShaderiv(s, GL_COMPILE_STATUS, &ok);
        if (ok != GL_TRUE) {
            char log[2048] = {};
            gl.GetShaderInfoLog(s, sizeof(log), nullptr, log);
            throw std::runtime_error(std::string("shader compile failed: ") + log);
        }
        return s;
    }
    GLuint program(const char* fragment) {
        GLuint p = gl.CreateProgram();
        GLuint v = shader(GL_VERTEX_SHADER, kVertexShader),
               f = shader(GL_FRAGMENT_SHADER, fragment);
        gl.AttachShader(p, v);
        gl.AttachShader(p, f);
        gl.LinkProgram(p);
        gl.DeleteShader(v);
        gl.DeleteShader(f);
        GLint ok = GL_FALSE;
        gl.GetProgramiv(p, GL_LINK_STATUS, &ok);
        if (ok != GL_TRUE) {
            char log[2048] = {};
            gl.GetProgramInfoLog(p, sizeof(log), nullptr, log);
            throw std::runtime_error(std::string("shader link failed: ") + log);
        }
        return p;
    }
    void upload(const Scene& scene, const RasterScene& raster) {
        // Per vertex: position, normal, the albedo of a triangle using it (a vertex belongs
        // to one object, so to one material).
        std::vector<float> vertices;
        std::vector<Vec3> albedo(raster.positions.size(), Vec3(0.8f));
        for (size_t t = 0; t < raster.triangles.size(); ++t)
            for (uint32_t v : raster.triangles[t])
                albedo[v] = scene.materials[size_t(raster.material[t])].albedo;
        for (size_t v = 0; v < raster.positions.size(); ++v) {
            const Vec3 p = raster.positions[v];
            const Vec3 n = v < raster.normals.size() ? raster.normals[v] : Vec3(0, 0, 1);
            vertices.insert(vertices.end(),
                            {p.x, p.y, p.z, n.x, n.y, n.z, albedo[v].x, albedo[v].y, albedo[v].z});
        }
        std::vector<uint32_t> indices;
        for (const auto& tri : raster.triangles)
            indices.insert(indices.end(), tri.begin(), tri.end());
        indexCount_ = GLsizei(indices.size());
        GLuint vao = 0, vbo = 0, ebo = 0;
        gl.GenVertexArrays(1, &vao);
        gl.BindVertexArray(vao);
        gl.GenBuffers(1, &vbo);
        gl.BindBuffer(GL_ARRAY_BUFFER, vbo);
        gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(float)), vertices.data(),
                      GL_STATIC_DRAW);
        gl.GenBuffers(1, &ebo);
        gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, ebo);
        gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(uint32_t)),
                      indices.data(), GL_STATIC_DRAW);
        for (GLuint a = 0; a < 3; ++a) {
            gl.EnableVertexAttribArray(a);
            gl.VertexAttribPointer(a, 3, GL_FLOAT, GL_FALSE, 9 * sizeof(float),
                                   reinterpret_cast<const void*>(size_t(3 * a) * sizeof(float)));
        }
        check("uploading the triangles");
    }
    void framebuffer() {
        GLuint fbo = 0, tex[3] = {};
        gl.GenFramebuffers(1, &fbo);
        gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
        gl.GenTextures(3, tex);
        // The triangle (32-bit), the colour (linear floats, as step 06's Image) and a 32-bit
        // float depth buffer.
        const GLint internal[3] = {GL_R32UI, GL_RGBA32F, GL_DEPTH_COMPONENT32F};
        const GLenum format[3] = {GL_RED_INTEGER, GL_RGBA, GL_DEPTH_COMPONENT};
        const GLenum type[3] = {GL_UNSIGNED_INT, GL_FLOAT, GL_FLOAT};
        const GLenum attach[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_DEPTH_ATTACHMENT};
        for (int i = 0; i < 3; ++i) {
            gl.BindTexture(GL_TEXTURE_2D, tex[i]);
            gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            gl.TexImage2D(GL_TEXTURE_2D, 0, internal[i], width_, height_, 0, format[i], type[i],
                          nullptr);
            gl.FramebufferTexture2D(GL_FRAMEBUFFER, attach[i], GL_TEXTURE_2D, tex[i], 0);
        }
        if (gl.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            throw std::runtime_error("the framebuffer is incomplete");
        gl.Viewport(0, 0, width_, height_);
        gl.ClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
        gl.Enable(GL_DEPTH_TEST);
        gl.DepthFunc(GL_GREATER);
        gl.Disable(GL_CULL_FACE);
        check("making the framebuffer");
    }

    int width_, height_;
    SDL_Window* window_ = nullptr;
    SDL_GLContext context_ = nullptr;
    GLuint visibility_ = 0, shaded_ = 0;
    GLsizei indexCount_ = 0;
    double near_ = 1.0;
    Vec3 background_{0.0f};
};

struct Sample {
    double wallMs = 0.0, cpuMs = 0.0;
};

// The median of `repeat` frames, wall and process CPU time (the CPU time includes the GL
// driver's rasterizer thread).
Sample timeFrames(int repeat, const std::function<void()>& frame) {
    std::vector<double> wall, cpu;
    for (int i = 0; i < repeat; ++i) {
        double c = processCpuSeconds();
        Stopwatch watch;
        frame();
        wall.push_back(watch.milliseconds());
        cpu.push_back((processCpuSeconds() - c) * 1e3);
    }
    return {summarize(wall).median, summarize(cpu).median};
}

double median(std::vector<double> v) {
    return summarize(std::move(v)).median;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Step 06 beside OpenGL on Mesa's llvmpipe: the bench's rasterizer row"};
    std::string sceneName = "bunny", dataDir = BOXES_DATA_DIR;
    bool inside = false;
    int width = 640, height = 480, repeat = 5, rounds = 3;
    app.add_option("--scene", sceneName, "built-in scene or an OBJ file")->capture_default_str();
    app.add_flag(
        "--inside", inside,
        "the interior map's camera: eye (960,-384,2) looking at (960,600,2), up z, fov 90");
    app.add_option("--width", width, "image width")
        ->check(CLI::Range(1, 8192))
        ->capture_default_str();
    app.add_option("--height", height, "image height")
        ->check(CLI::Range(1, 8192))
        ->capture_default_str();
    app.add_option("--repeat", repeat, "frames per variant and round (their median)")
        ->check(CLI::Range(1, 1000))
        ->capture_default_str();
    app.add_option("--rounds", rounds, "rounds of every variant, alternating")
        ->check(CLI::Range(1, 100))
        ->capture_default_str();
    app.add_option("--data", dataDir, "the workbook's data folder")->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    // llvmpipe, one rasterizer thread, no display: unless the caller chose otherwise.
    setenv("SDL_VIDEODRIVER", "offscreen", 0);
    setenv("LIBGL_ALWAYS_SOFTWARE", "1", 0);
    setenv("GALLIUM_DRIVER", "llvmpipe", 0);
    setenv("LP_NUM_THREADS", "1", 0);
    try {
        const float aspect = float(width) / float(height);
        Scene scene = makeScene(sceneName, {dataDir, aspect});
        Camera camera = scene.camera;
        if (inside)
            camera = Camera::lookingAt(Vec3(960, -384, 2), Vec3(960, 600, 2), Vec3(0, 0, 1), 90.0f,
                                       aspect);
        RasterView view(scene);
        view.raster.width = width;
        view.raster.height = height;
        view.shading.shadows = ShadowMode::None;
        auto [near, far] = nearFarFor(view.scene, camera, view.raster);
        GlRaster gl(scene, view.scene, width, height);
        gl.setView(scene, camera, near, far);

        // The variants, in the order each round runs them. Step 06 as its program draws
        // (frustum culling with step 04's hierarchy), and without the culling.
        FrameBuffers buffers;
        CullStats cull;
        FrameStats stats;
        RasterFrame shadedFrame;
        RasterView noCull(scene);
        noCull.raster = view.raster;
        noCull.shading = view.shading;
        noCull.culling = false;
        struct Variant {
            const char* name;
            std::function<void()> frame;
            std::vector<Sample> rounds;
        };
        std::vector<Variant> variants = {
            {"step06 visibility",
             [&] {
                 rasterizeCulled(view.scene, view.culler.get(), camera, view.raster, buffers, cull);
             },
             {}},
            {"llvmpipe visibility", [&] { gl.draw(GlRaster::Pass::Visibility); }, {}},
            {"step06 shaded", [&] { shadedFrame = drawFrame(scene, view, camera); }, {}},
            {"llvmpipe shaded", [&] { gl.draw(GlRaster::Pass::Shaded); }, {}},
            {"step06 visibility, no culling",
             [&] { rasterizeCulled(noCull.scene, nullptr, camera, noCull.raster, buffers, cull); },
             {}},
            {"llvmpipe depth only", [&] { gl.draw(GlRaster::Pass::DepthOnly); }, {}},
        };
        for (Variant& v : variants) v.frame();  // warm up: shaders compiled, caches filled
        for (int r = 0; r < rounds; ++r)
            for (Variant& v : variants) v.rounds.push_back(timeFrames(repeat, v.frame));

        // Agreement: the same triangle per pixel, visibility and shaded.
        std::vector<uint32_t> glIds;
        std::vector<float> glDepth;
        nlohmann::json agree;
        stats = rasterizeCulled(view.scene, view.culler.get(), camera, view.raster, buffers, cull);
        for (bool shaded : {false, true}) {
            gl.draw(shaded ? GlRaster::Pass::Shaded : GlRaster::Pass::Visibility);
            gl.read(glIds, glDepth);
            const FrameBuffers& ours = shaded ? shadedFrame.buffers : buffers;
            VisibilityComparison c =
                compareVisibility(width, height, ours.triangle, ours.depth, glIds, glDepth);
            agree[shaded ? "shaded" : "visibility"] = {
                {"same_triangle_share", c.agreement()},  {"covered_step06", c.coveredRaster},
                {"covered_llvmpipe", c.coveredTraced},   {"differ_on_edges", c.differOnEdge},
                {"differ_elsewhere", c.differElsewhere}, {"max_depth_error", c.maxDepthError}};
        }

        nlohmann::json out;
        out["scene"] = sceneName;
        out["camera"] = inside ? "inside" : "scene";
        out["width"] = width;
        out["height"] = height;
        out["triangles"] = view.scene.triangles.size();
        out["triangles_after_culling"] = cull.trianglesKept;
        // Step 06's work per frame: pixel centres covered before the depth test.
        out["fragments"] = stats.fragments;
        out["triangles_drawn"] = stats.trianglesDrawn;
        out["repeat"] = repeat;
        out["rounds"] = rounds;
        out["renderer"] = gl.renderer;
        out["lp_num_threads"] = std::getenv("LP_NUM_THREADS");
        out["agreement"] = agree;
        for (const Variant& v : variants) {
            std::vector<double> wall, cpu;
            for (const Sample& s : v.rounds) wall.push_back(s.wallMs), cpu.push_back(s.cpuMs);
            out["variants"][v.name] = {{"ms", wall}, {"cpu_ms", cpu}};
        }
        // Per round, llvmpipe's time over step 06's (above 1: step 06 is faster); their median.
        auto ratios = [&](size_t ours, size_t theirs, bool cpuTime) {
            std::vector<double> r;
            for (int i = 0; i < rounds; ++i) {
                const Sample &a = variants[ours].rounds[size_t(i)],
                             &b = variants[theirs].rounds[size_t(i)];
                r.push_back(cpuTime ? b.cpuMs / a.cpuMs : b.wallMs / a.wallMs);
            }
            std::sort(r.begin(), r.end());
            return nlohmann::json{{"median", median(r)}, {"rounds", r}};
        };
        out["speed_vs_llvmpipe"] = {{"visibility", ratios(0, 1, false)},
                                    {"shaded", ratios(2, 3, false)},
                                    {"visibility_no_culling", ratios(4, 1, false)},
                                    {"visibility_vs_depth_only", ratios(0, 5, false)}};
        out["cpu_speed_vs_llvmpipe"] = {{"visibility", ratios(0, 1, true)},
                                        {"shaded", ratios(2, 3, true)},
                                        {"visibility_no_culling", ratios(4, 1, true)},
                                        {"visibility_vs_depth_only", ratios(0, 5, true)}};
        std::cout << out.dump() << "\n";
    } catch (const std::exception& e) {
        std::cerr << "raster_gl: " << e.what() << "\n";
        return 1;
    }
    return 0;
}
