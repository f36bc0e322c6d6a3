// Intel Embree 3 (Debian's libembree-dev) as a second tracer beside step 04's engine: the
// same mesh (read by the core's OBJ reader, so triangle i is the same triangle in both),
// the same rays, hits in the same form (TraceHit: t and triangle index).
#pragma once

#include <embree3/rtcore.h>

#include <string>
#include <vector>

#include "04_bvh/trace.hpp"

namespace boxes {

class EmbreeTracer {
public:
    // config: Embree's device configuration ("threads=1", "verbose=3", ...); quality: its
    // build quality (the bench uses high, Embree's best tree).
    EmbreeTracer(const Mesh& mesh, const std::string& config,
                 RTCBuildQuality quality = RTC_BUILD_QUALITY_HIGH);
    ~EmbreeTracer();
    EmbreeTracer(const EmbreeTracer&) = delete;
    EmbreeTracer& operator=(const EmbreeTracer&) = delete;

    // The nearest hit of every ray with rtcIntersect1, on `threads` threads (chunks taken
    // in turn, so a thread that got cheap rays takes more).
    void trace(const std::vector<Ray>& rays, std::vector<TraceHit>& hits, int threads) const;
    double buildMs() const { return buildMs_; }

private:
    void release();
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    double buildMs_ = 0.0;
    std::string error_;  // the first error Embree reported
};

}  // namespace boxes
