#include "core/render.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cfenv>
#include <chrono>
#include <cstdio>
#include <exception>
#include <mutex>
#include <random>
#include <thread>
#include <vector>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace boxes {

RayCounts& RayCounts::operator+=(const RayCounts& o) {
    primary += o.primary;
    shadow += o.shadow;
    reflection += o.reflection;
    refraction += o.refraction;
    shadowSkipped += o.shadowSkipped;
    lightsOutOfRange += o.lightsOutOfRange;
    return *this;
}

namespace {

bool boxTouchesBall(Vec3 lo, Vec3 hi, Vec3 centre, float radius) {
    if (!std::isfinite(radius)) return true;
    Vec3 nearest = glm::clamp(centre, lo, hi);
    Vec3 d = nearest - centre;
    return glm::dot(d, d) <= radius * radius;
}

}  // namespace

SceneAnalysis analyzeScene(const Scene& scene, const AnalysisParts& parts) {
    SceneAnalysis a;
    a.parts = parts;
    for (size_t i = 0; i < scene.spheres.size(); ++i) {
        a.convex.push_back(true);
        a.isPlane.push_back(false);
    }
    for (size_t i = 0; i < scene.planes.size(); ++i) {
        a.convex.push_back(true);
        a.isPlane.push_back(true);
    }
    for (const auto& g : scene.geometries) {
        a.convex.push_back(g->convex());
        a.isPlane.push_back(false);
    }
    // An object outside a light's ball of influence cannot block that light for any lit
    // point: the segment from a lit point to the light lies inside the (convex) ball.
    // Without light ranges a point beyond the radius is shaded too: no ball to rely on.
    const bool perLight = parts.occludersPerLight && parts.lightRanges;
    for (const PointLight& light : scene.lights) {
        const float radius = perLight ? light.radius : kInfinity<float>;
        std::vector<int> list;
        int object = 0;
        for (const auto& s : scene.spheres) {
            Vec3 r(s.shape.radius);
            if (boxTouchesBall(s.shape.centre - r, s.shape.centre + r, light.position, radius))
                list.push_back(object);
            ++object;
        }
        for (size_t i = 0; i < scene.planes.size(); ++i) list.push_back(object++);
        for (const auto& g : scene.geometries) {
            if (boxTouchesBall(g->boundsMin(), g->boundsMax(), light.position, radius))
                list.push_back(object);
            ++object;
        }
        a.occluders.push_back(std::move(list));
    }
    return a;
}

Vec3 offsetOrigin(const Vec3& point, const Vec3& geometricNormal, const Vec3& direction) {
    // The offset grows with the coordinates' magnitude: float spacing does too.
    float scale = 1e-4f * (1.0f + maxComponent(glm::abs(point)));
    Vec3 n = glm::dot(geometricNormal, direction) >= 0.0f ? geometricNormal : -geometricNormal;
    return point + scale * n;
}

FacingNormals facingNormals(const Vec3& direction, const SurfaceHit& hit) {
    bool entering = glm::dot(direction, hit.geometricNormal) < 0.0f;
    Vec3 ng = entering ? hit.geometricNormal : -hit.geometricNormal;
    Vec3 n = glm::dot(hit.shadingNormal, ng) >= 0.0f ? hit.shadingNormal : -hit.shadingNormal;
    return {ng, n};
}

DirectLight directLight(const Material& m, const PointLight& light, const Vec3& point,
                        const FacingNormals& normals) {
    DirectLight d;
    d.toLight = light.position - point;
    float dist2 = glm::dot(d.toLight, d.toLight);
    float cosine = glm::dot(normals.shading, d.toLight);
    d.inRange = dist2 <= light.radius * light.radius;
    d.facing = cosine > 0.0f && glm::dot(normals.geometric, d.toLight) > 0.0f;
    if (d.contributes())
        d.radiance = m.albedo * light.intensity * (cosine / (dist2 * std::sqrt(dist2)));
    return d;
}

Renderer::Renderer(const Scene& scene, const Camera& camera, const RenderSettings& settings)
    : scene_(scene), camera_(camera), settings_(settings) {
    if (settings.width <= 0 || settings.height <= 0)
        throw std::invalid_argument("image size must be positive");
    if (settings.samplesPerPixel < 1) throw std::invalid_argument("samples per pixel must be >= 1");
    scene.checkRenderable();
    basis_ = camera_.basis();
    analysis_ = analyzeScene(scene, settings.analysis);
}

bool Renderer::needsShadowRay(int light, const SurfaceHit& hit) const {
    const Vec3 lightPos = scene_.lights[size_t(light)].position;
    for (int object : analysis_.occluders[size_t(light)]) {
        if (object == hit.object) {
            // A convex object cannot shadow a point of its outside; seen from inside (the
            // camera in a sphere) it blocks every light beyond it.
            bool inside = glm::dot(hit.geometricNormal, lightPos - hit.point) < 0.0f &&
                          !analysis_.isPlane[size_t(object)];
            if (!analysis_.parts.convexSelf || !analysis_.convex[size_t(object)] || inside)
                return true;
            continue;
        }
        if (analysis_.parts.planeSides && analysis_.isPlane[size_t(object)]) {
            // A plane blocks only points on the other side from the light.
            const Plane& p = scene_.planes[size_t(object) - scene_.spheres.size()].shape;
            float sp = glm::dot(p.normal, hit.point) + p.d;
            float sl = glm::dot(p.normal, lightPos) + p.d;
            if ((sp > 0.0f && sl > 0.0f) || (sp < 0.0f && sl < 0.0f)) continue;
        }
        return true;
    }
    return false;
}

Vec3 Renderer::shade(const Ray& ray, const SurfaceHit& hit, int depth, RayCounts& counts) const {
    const Material& m = scene_.materials[size_t(hit.material)];
    const bool force = settings_.forceAllEffects;
    // Shade the side the ray arrives from.
    bool entering = glm::dot(ray.direction, hit.geometricNormal) < 0.0f;
    FacingNormals normals = facingNormals(ray.direction, hit);
    Vec3 ng = normals.geometric;

    Vec3 colour(0.0f);
    if (m.kind == Material::Kind::Diffuse) {
        colour = scene_.ambient * m.albedo;
        for (size_t i = 0; i < scene_.lights.size(); ++i) {
            DirectLight light = directLight(m, scene_.lights[i], hit.point, normals);
            if (!light.inRange) ++counts.lightsOutOfRange;
            bool contributes = light.contributes();
            // Behind the surface the light has zero weight; beyond its radius too, but
            // only the analysis' light ranges may skip that shadow ray.
            bool needed = analysis_.parts.lightRanges ? contributes : light.facing;
            if (!needed && !force) continue;
            bool shadowNeeded = needsShadowRay(int(i), hit);
            bool visible = true;
            if (shadowNeeded || force) {
                ++counts.shadow;
                Ray shadowRay(offsetOrigin(hit.point, hit.geometricNormal, light.toLight),
                              light.toLight, 0.0f, 1.0f - 1e-5f);
                visible = !scene_.occluded(shadowRay);
            } else {
                ++counts.shadowSkipped;
            }
            if (contributes && visible) colour += light.radiance;
        }
    }
    if (depth >= settings_.maxDepth) return colour;

    // Mirror reflection, and for glass reflection and refraction weighted by Fresnel.
    float reflectWeight = 0.0f, refractWeight = 0.0f;
    Vec3 tint(1.0f);
    Vec3 refracted(0.0f);
    bool canRefract = false;
    Vec3 d = glm::normalize(ray.direction);
    if (m.kind == Material::Kind::Mirror) {
        reflectWeight = m.reflectance;
        tint = m.albedo;
    } else if (m.kind == Material::Kind::Glass) {
        float nFrom = entering ? 1.0f : m.ior, nTo = entering ? m.ior : 1.0f;
        float cosI = -glm::dot(d, ng);
        canRefract = refract(d, ng, nFrom / nTo, refracted);
        reflectWeight = canRefract ? fresnelDielectric(cosI, nFrom, nTo) : 1.0f;
        refractWeight = 1.0f - reflectWeight;
    }
    if (reflectWeight > 0.0f || force) {
        ++counts.reflection;
        Vec3 r = reflect(d, ng);
        Vec3 c = trace(Ray(offsetOrigin(hit.point, hit.geometricNormal, r), r), depth + 1, counts);
        colour += reflectWeight * tint * c;
    }
    if (refractWeight > 0.0f || force) {
        ++counts.refraction;
        Vec3 t = canRefract ? refracted : d;
        Vec3 c = trace(Ray(offsetOrigin(hit.point, hit.geometricNormal, t), t), depth + 1, counts);
        colour += refractWeight * c;
    }
    return colour;
}

Vec3 Renderer::trace(const Ray& ray, int depth, RayCounts& counts) const {
    SurfaceHit hit;
    if (!scene_.intersect(ray, hit)) return scene_.background;
    return shade(ray, hit, depth, counts);
}

Vec3 Renderer::pixel(int x, int y, RayCounts& counts) const {
    const int w = settings_.width, h = settings_.height;
    const int spp = settings_.samplesPerPixel;
    if (spp == 1) {
        ++counts.primary;
        Ray ray(camera_.eye,
                camera_.directionThrough(basis_, float(x) + 0.5f, float(y) + 0.5f, w, h));
        return trace(ray, 0, counts);
    }
    // Stratified samples: an n x n grid (n = ceil(sqrt(spp))), jittered, the first spp taken.
    int n = int(std::ceil(std::sqrt(double(spp))));
    std::mt19937_64 rng(settings_.seed * 0x9E3779B97F4A7C15ull + uint64_t(y) * uint64_t(w) +
                        uint64_t(x));
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    Vec3 sum(0.0f);
    for (int s = 0; s < spp; ++s) {
        float sx = (float(s % n) + uniform(rng)) / float(n);
        float sy = (float(s / n) + uniform(rng)) / float(n);
        ++counts.primary;
        Ray ray(camera_.eye, camera_.directionThrough(basis_, float(x) + sx, float(y) + sy, w, h));
        sum += trace(ray, 0, counts);
    }
    return sum / float(spp);
}

void Renderer::renderRows(Image& image, int rowBegin, int rowEnd, RayCounts& counts) const {
    for (int y = rowBegin; y < rowEnd; ++y)
        for (int x = 0; x < settings_.width; ++x) {
            checkCancelled(settings_.control);  // a slow row stops within a pixel
            image.at(x, y) = pixel(x, y, counts);
        }
}

void checkCancelled(const RenderControl* control) {
    if (control && control->cancel.load(std::memory_order_relaxed)) throw RenderCancelled();
}

Image Renderer::render(RayCounts* counts) const {
    Image image(settings_.width, settings_.height);
    int threads = resolveThreads(settings_.threads);
    std::vector<RayCounts> perThread(static_cast<size_t>(threads));
    RenderControl* control = settings_.control;
    if (control) {
        control->rowsDone = 0;
        control->rows = settings_.height;
    }
    parallelRows(
        settings_.height, threads,
        [&](int row, int thread) {
            checkCancelled(control);  // a thrown stop ends the other threads' rows too
            renderRows(image, row, row + 1, perThread[size_t(thread)]);
            if (control) control->rowsDone.fetch_add(1, std::memory_order_relaxed);
        },
        settings_.progressLabel);
    if (counts)
        for (const RayCounts& c : perThread) *counts += c;
    return image;
}

Image renderImage(const Scene& scene, const Camera& camera, const RenderSettings& settings,
                  RayCounts* counts) {
    return Renderer(scene, camera, settings).render(counts);
}

void parallelRows(int rows, int threads, const std::function<void(int, int)>& body,
                  const std::string& label) {
    threads = std::max(1, std::min(resolveThreads(threads), rows));
    std::atomic<int> next{0};
    std::atomic<int> done{0};
    std::mutex printMutex;
    const auto started = std::chrono::steady_clock::now();
    auto seconds = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    };
    std::atomic<double> lastPrint{0.0};
    const bool tty = isatty(fileno(stderr));
    auto report = [&](bool final) {
        if (label.empty() || seconds() < 1.0) return;
        std::lock_guard<std::mutex> lock(printMutex);
        double now = seconds();
        if (!final && now - lastPrint.load() < (tty ? 0.2 : 5.0)) return;
        lastPrint = now;
        int percent = int(100.0 * done.load() / rows);
        std::fprintf(stderr, tty ? "\r%s: %3d%% (%.1f s)%s" : "%s: %3d%% (%.1f s)%s\n",
                     label.c_str(), percent, now, final && tty ? "\n" : "");
        std::fflush(stderr);
    };
    runOnThreads(threads, [&](int thread) {
        try {
            for (int row; (row = next.fetch_add(1)) < rows;) {
                body(row, thread);
                ++done;
                report(false);
            }
        } catch (...) {
            next = rows;  // stop the others
            throw;
        }
    });
    report(true);
}

// ---- Threads -------------------------------------------------------------------------------

int resolveThreads(int threads) {
    return threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
}

namespace {

// One call of runOnThreads: the task, the caller's floating-point environment, and the
// first exception.
struct Call {
    const std::function<void(int)>* task = nullptr;
    std::fenv_t fpEnvironment;
    std::mutex failureMutex;
    std::exception_ptr failure;

    void run(int thread) {
        try {
            (*task)(thread);
        } catch (...) {
            std::lock_guard lock(failureMutex);
            if (!failure) failure = std::current_exception();
        }
    }
};

// Spins for about a millisecond, then sleeps, until `value` is no longer `old`: a repeated
// trace or the next frame starts within microseconds, and waking a sleeping thread costs a
// noticeable share of a short parallel pass.
template <typename T>
T awaitChange(const std::atomic<T>& value, T old) {
    auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(1);
    for (int spin = 0;; ++spin) {
        T now = value.load(std::memory_order_acquire);
        if (now != old) return now;
        if ((spin & 63) == 0 && std::chrono::steady_clock::now() > until) break;
#if defined(__SSE2__)
        _mm_pause();
#endif
    }
    value.wait(old, std::memory_order_acquire);
    return value.load(std::memory_order_acquire);
}

class WorkerPool {
public:
    ~WorkerPool() { resize(0); }

    // false when the pool is busy: the caller then starts threads of its own.
    bool run(Call& call, int threads) {
        if (busy_.exchange(true, std::memory_order_acquire)) return false;
        struct Release {
            std::atomic<bool>& busy;
            ~Release() { busy.store(false, std::memory_order_release); }
        } release{busy_};
        resize(size_t(threads - 1));
        call_ = &call;
        pending_.store(int(workers_.size()), std::memory_order_relaxed);
        generation_.fetch_add(1, std::memory_order_release);
        generation_.notify_all();
        call.run(0);
        for (int left = pending_.load(std::memory_order_acquire); left != 0;)
            left = awaitChange(pending_, left);
        return true;
    }

private:
    void resize(size_t workers) {
        if (workers_.size() == workers) return;
        if (!workers_.empty()) {
            stop_.store(true, std::memory_order_relaxed);
            generation_.fetch_add(1, std::memory_order_release);
            generation_.notify_all();
            for (std::thread& t : workers_) t.join();
            workers_.clear();
            stop_.store(false, std::memory_order_relaxed);
        }
        uint64_t current = generation_.load(std::memory_order_relaxed);
        for (size_t i = 0; i < workers; ++i)
            workers_.emplace_back([this, current, i] { work(int(i) + 1, current); });
    }

    void work(int thread, uint64_t seen) {
        for (;;) {
            seen = awaitChange(generation_, seen);
            if (stop_.load(std::memory_order_relaxed)) return;
            std::fesetenv(&call_->fpEnvironment);
            call_->run(thread);
            if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) pending_.notify_one();
        }
    }

    std::atomic<bool> busy_{false};
    std::vector<std::thread> workers_;
    std::atomic<uint64_t> generation_{0};
    std::atomic<int> pending_{0};
    std::atomic<bool> stop_{false};
    Call* call_ = nullptr;
};

WorkerPool& workerPool() {
    static WorkerPool pool;
    return pool;
}

}  // namespace

void runOnThreads(int threads, const std::function<void(int)>& task) {
    threads = resolveThreads(threads);
    if (threads == 1) return task(0);
    Call call;
    call.task = &task;
    std::fegetenv(&call.fpEnvironment);
    if (!workerPool().run(call, threads)) {
        std::vector<std::thread> own;
        for (int t = 1; t < threads; ++t) own.emplace_back([&call, t] { call.run(t); });
        call.run(0);
        for (std::thread& t : own) t.join();
    }
    if (call.failure) std::rethrow_exception(call.failure);
}

}  // namespace boxes
