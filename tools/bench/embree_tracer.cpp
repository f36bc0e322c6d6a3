#include "embree_tracer.hpp"

#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <stdexcept>
#include <thread>

#include "core/timing.hpp"

namespace boxes {

namespace {

// Embree reports errors through a callback from its C code: no exception may pass through
// it, so the first message is kept and thrown once control is back in ours.
void onError(void* user, RTCError code, const char* text) {
    auto* message = static_cast<std::string*>(user);
    if (message->empty())
        *message = "Embree error " + std::to_string(int(code)) + ": " + (text ? text : "");
}

// Embree's own advice for its traversal: denormals flushed to zero, per thread.
void flushDenormals() {
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

void traceRange(RTCScene scene, const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                size_t begin, size_t end) {
    flushDenormals();
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (size_t i = begin; i < end; ++i) {
        const Ray& r = rays[i];
        RTCRayHit rh{};
        rh.ray.org_x = r.origin.x;
        rh.ray.org_y = r.origin.y;
        rh.ray.org_z = r.origin.z;
        rh.ray.tnear = r.tmin;
        rh.ray.dir_x = r.direction.x;
        rh.ray.dir_y = r.direction.y;
        rh.ray.dir_z = r.direction.z;
        rh.ray.tfar = r.tmax;
        rh.ray.mask = ~0u;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &context, &rh);
        hits[i] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID ? TraceHit{}
                                                           : TraceHit{rh.ray.tfar, rh.hit.primID};
    }
}

}  // namespace

EmbreeTracer::EmbreeTracer(const Mesh& mesh, const std::string& config, RTCBuildQuality quality) {
    device_ = rtcNewDevice(config.c_str());
    if (!device_) throw std::runtime_error("Embree: rtcNewDevice('" + config + "') failed");
    rtcSetDeviceErrorFunction(device_, onError, &error_);
    scene_ = rtcNewScene(device_);
    rtcSetSceneBuildQuality(scene_, quality);
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geometry, quality);
    // Buffers Embree allocates itself carry the padding its vector loads need.
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh.positions.size()));
    for (size_t i = 0; i < mesh.positions.size(); ++i)
        std::memcpy(vertices + 3 * i, &mesh.positions[i], 3 * sizeof(float));
    auto* indices = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(uint32_t), mesh.triangles.size()));
    std::memcpy(indices, mesh.triangles.data(), mesh.triangles.size() * 3 * sizeof(uint32_t));
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene_, geometry);
    rtcReleaseGeometry(geometry);
    Stopwatch watch;
    rtcCommitScene(scene_);
    buildMs_ = watch.milliseconds();
    if (!error_.empty()) {
        release();
        throw std::runtime_error(error_);
    }
}

EmbreeTracer::~EmbreeTracer() {
    release();
}

void EmbreeTracer::release() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
    scene_ = nullptr;
    device_ = nullptr;
}

void EmbreeTracer::trace(const std::vector<Ray>& rays, std::vector<TraceHit>& hits,
                         int threads) const {
    hits.assign(rays.size(), TraceHit{});
    if (threads <= 1) {
        traceRange(scene_, rays, hits, 0, rays.size());
        return;
    }
    constexpr size_t kChunk = 4096;
    std::atomic<size_t> next{0};
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t)
        pool.emplace_back([&] {
            for (size_t b; (b = next.fetch_add(kChunk)) < rays.size();)
                traceRange(scene_, rays, hits, b, std::min(rays.size(), b + kChunk));
        });
    for (std::thread& t : pool) t.join();
}

}  // namespace boxes
