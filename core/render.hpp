// A Whitted-style ray tracer: direct light with shadow rays, mirror reflection, glass
// with Fresnel and total internal reflection, up to a maximum depth. It simulates only
// the effects the scene calls for (the image is the same as with every effect traced) and
// counts every ray it traces; and the threads it renders on.
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "core/scene.hpp"

namespace boxes {

struct RayCounts {
    uint64_t primary = 0, shadow = 0, reflection = 0, refraction = 0;
    uint64_t shadowSkipped = 0;     // shadow rays the scene analysis proved unnecessary
    uint64_t lightsOutOfRange = 0;  // light evaluations beyond the light's radius
    uint64_t total() const { return primary + shadow + reflection + refraction; }
    RayCounts& operator+=(const RayCounts& o);
};

// The parts of the scene analysis the renderer uses (all by default). With every part off
// it still skips the rays of zero weight (lights behind the surface, zero reflectance, no
// refraction): the fair baseline the analysis is measured against.
struct AnalysisParts {
    bool occludersPerLight = true;  // only objects whose bounds reach a light's ball block it
    bool planeSides = true;         // a plane blocks only points on the far side from the light
    bool convexSelf = true;         // a convex object cannot shadow its own outside
    bool lightRanges = true;        // no shadow ray to a light beyond its radius
    static AnalysisParts none() { return {false, false, false, false}; }
};

// A render another thread can follow and stop (the window renders on a thread of its own,
// so it answers keys while a slow image is made): rows finished so far, and a request to
// stop, which the renderer honours between rows by throwing RenderCancelled.
struct RenderControl {
    std::atomic<int> rowsDone{0}, rows{0};
    std::atomic<bool> cancel{false};
    double progress() const { return rows > 0 ? double(rowsDone) / double(rows) : 0.0; }
};
struct RenderCancelled : std::exception {
    const char* what() const noexcept override { return "render cancelled"; }
};
// Throws RenderCancelled when `control` asks to stop (no-op without a control): for a
// step's own loop over rows.
void checkCancelled(const RenderControl* control);

struct RenderSettings {
    int width = 640;
    int height = 480;
    int maxDepth = 5;         // primary rays are depth 0
    int threads = 0;          // 0: every hardware thread
    int samplesPerPixel = 1;  // > 1: stratified jitter within the pixel
    uint64_t seed = 1;
    AnalysisParts analysis;            // which parts of the scene analysis skip shadow rays
    bool forceAllEffects = false;      // trace every ray, zero weights too (naive renderer)
    std::string progressLabel;         // when set, long renders print progress to stderr
    RenderControl* control = nullptr;  // when set: progress per row, and a way to stop
};

// Which objects can block which light, derived once from the scene.
struct SceneAnalysis {
    AnalysisParts parts;
    // occluders[light]: objects that may block that light somewhere (their bounds reach
    // the light's sphere of influence; every object without occludersPerLight or
    // lightRanges); planes are checked per point by side.
    std::vector<std::vector<int>> occluders;
    std::vector<bool> convex;  // per object: cannot shadow itself
    std::vector<bool> isPlane;
};
SceneAnalysis analyzeScene(const Scene& scene, const AnalysisParts& parts = {});

class Renderer {
public:
    Renderer(const Scene& scene, const Camera& camera, const RenderSettings& settings);

    Image render(RayCounts* counts = nullptr) const;
    // Renders rows [rowBegin, rowEnd) of `image` (single thread), adding to counts.
    void renderRows(Image& image, int rowBegin, int rowEnd, RayCounts& counts) const;
    Vec3 pixel(int x, int y, RayCounts& counts) const;
    // Radiance along a ray; depth 0 is a primary ray.
    Vec3 trace(const Ray& ray, int depth, RayCounts& counts) const;

    const SceneAnalysis& analysis() const { return analysis_; }
    const RenderSettings& settings() const { return settings_; }
    // The analysis' decision for a lit point: false when no object can block the light
    // there (its shadow ray is skipped). Public so that the tests can check it is sound.
    bool needsShadowRay(int light, const SurfaceHit& hit) const;

private:
    Vec3 shade(const Ray& ray, const SurfaceHit& hit, int depth, RayCounts& counts) const;

    const Scene& scene_;
    Camera camera_;
    CameraBasisT<float> basis_;
    RenderSettings settings_;
    SceneAnalysis analysis_;
};

// Renders the whole image with the scene's geometry (rows in parallel).
Image renderImage(const Scene& scene, const Camera& camera, const RenderSettings& settings,
                  RayCounts* counts = nullptr);

// Runs body(row) for every row on `threads` threads (0: all; the caller and kept workers,
// see runOnThreads below), rows handed out one at a time; prints progress for long runs
// when label is not empty. The first exception from body stops the rest and is rethrown.
void parallelRows(int rows, int threads, const std::function<void(int row, int thread)>& body,
                  const std::string& label = "");

// The normals of a hit as seen by a viewer looking along `direction`: the geometric normal
// turned towards the viewer, the shading normal turned to the same side. Shared by the ray
// tracer and step 06's rasterizer so both shade a point the same way.
struct FacingNormals {
    Vec3 geometric, shading;
};
FacingNormals facingNormals(const Vec3& direction, const SurfaceHit& hit);

// What one point light gives a diffuse point before any shadow test:
// albedo * intensity * cos / d^2 (cosine with the shading normal), and whether it can
// contribute at all (in range, and in front of both normals).
struct DirectLight {
    Vec3 toLight{0.0f};  // unnormalized, from the point to the light
    Vec3 radiance{0.0f};
    bool inRange = false, facing = false;
    bool contributes() const { return inRange && facing; }
};
DirectLight directLight(const Material& material, const PointLight& light, const Vec3& point,
                        const FacingNormals& normals);

// Shadow and secondary rays start slightly off the surface, on the side they leave
// towards, so they do not hit the surface they start on (self-intersection acne).
Vec3 offsetOrigin(const Vec3& point, const Vec3& geometricNormal, const Vec3& direction);

// ---- Threads -------------------------------------------------------------------------------

// Work on several threads: the calling thread and worker threads kept from one call to the
// next. Every step's renderer (parallelRows) and step 04's batch tracer run on it.
//
// Why kept workers, and why the caller works too: starting threads for every call costs
// about as much as a short batch of rays takes, and a caller that only waits in join()
// leaves a core idle; so the caller works beside workers that wait for the next call.

// The thread count a `threads` setting means: 0 (or less) is every hardware thread.
int resolveThreads(int threads);

// Runs task(thread) once on each of `threads` threads (0: all), thread 0 being the caller;
// returns when every one has returned. Workers take the caller's floating-point
// environment (rounding mode, enabled traps) as threads started for the call would. The
// first exception a task throws is rethrown here once all have returned; ending the other
// tasks early is the task's own business (they share whatever counter hands out work).
// A call made while the kept workers are busy (from another thread, or from inside a
// task) starts threads of its own.
void runOnThreads(int threads, const std::function<void(int thread)>& task);

}  // namespace boxes
