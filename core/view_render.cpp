#include "core/view_render.hpp"

#include <algorithm>
#include <vector>

#include "core/timing.hpp"

namespace boxes {

void ViewRender::start(RenderFn render, const RenderSettings& full) {
    stop();
    {
        std::lock_guard<std::mutex> lock(mutex_);
        busy_ = true;
        complete_ = false;
        pass_.clear();
    }
    control_.cancel = false;
    control_.rowsDone = 0;
    control_.rows = 0;
    thread_ = std::thread(&ViewRender::run, this, std::move(render), full);
}

void ViewRender::stop() {
    control_.cancel = true;
    if (thread_.joinable()) thread_.join();
    std::lock_guard<std::mutex> lock(mutex_);
    busy_ = false;
}

void ViewRender::finish() {
    if (thread_.joinable()) thread_.join();
}

void ViewRender::run(RenderFn render, RenderSettings full) {
    // The passes: 1/8 and 1/2 of the size where that leaves at least a few pixels, then full.
    std::vector<std::pair<int, std::string>> passes;
    for (auto [divisor, name] : {std::pair{8, "1/8 size"}, std::pair{2, "1/2 size"}})
        if (full.width / divisor >= 16 && full.height / divisor >= 12)
            passes.emplace_back(divisor, name);
    passes.emplace_back(1, "full size");
    try {
        for (const auto& [divisor, name] : passes) {
            {
                std::lock_guard<std::mutex> lock(mutex_);
                pass_ = name;
            }
            RenderSettings settings = full;
            settings.width = std::max(1, full.width / divisor);
            settings.height = std::max(1, full.height / divisor);
            settings.control = &control_;
            settings.progressLabel.clear();
            Stopwatch watch;
            Image image = render(settings);
            checkCancelled(&control_);  // a stop asked for after the last row
            std::lock_guard<std::mutex> lock(mutex_);
            ready_ = std::move(image);
            fresh_ = true;
            if (divisor == 1) {
                complete_ = true;
                fullMs_ = watch.milliseconds();
            }
        }
    } catch (const RenderCancelled&) {
        // A new view or the end of the window: nothing to show from this one.
    } catch (...) {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    busy_ = false;
    pass_.clear();
}

bool ViewRender::busy() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return busy_;
}

bool ViewRender::take(Image& image) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
    if (!fresh_) return false;
    image = std::move(ready_);
    ready_ = Image();
    fresh_ = false;
    return true;
}

std::pair<double, std::string> ViewRender::progress() const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!busy_ || pass_.empty()) return {-1.0, ""};
    return {control_.progress(), "rendering " + pass_};
}

bool ViewRender::complete() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return complete_;
}

double ViewRender::fullMs() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return fullMs_;
}

}  // namespace boxes
