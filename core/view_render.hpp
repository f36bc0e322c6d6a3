// The window's view made on a thread of its own, coarse first and then finer (step 05's
// progressive way: something at once, the full picture as soon as it is ready), so the
// window answers its keys and shows the progress while a slow image is made.
#pragma once

#include <exception>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include "core/image.hpp"
#include "core/render.hpp"

namespace boxes {

class ViewRender {
public:
    // Renders the view at the given settings (their size and control), on the render thread.
    using RenderFn = std::function<Image(const RenderSettings& settings)>;

    ViewRender() = default;
    ~ViewRender() { stop(); }
    ViewRender(const ViewRender&) = delete;
    ViewRender& operator=(const ViewRender&) = delete;

    // Starts the view anew (stopping the one under way): passes at 1/8 and 1/2 of the size
    // of `full` when they are smaller than it, then `full` itself. render must return an
    // image of the settings' size, or throw (RenderCancelled when asked to stop).
    void start(RenderFn render, const RenderSettings& full);
    // Asks the render to stop and waits for it: a renderer that checks settings.control
    // stops within a row. The last finished pass stays available.
    void stop();
    // Waits for the passes to end without stopping them (a scripted window's last frame).
    void finish();

    // True while a pass is under way.
    bool busy() const;
    // Moves the newest finished pass into `image` when there is one it has not given yet.
    // Rethrows what the render threw (other than RenderCancelled), on the caller's thread.
    bool take(Image& image);
    // The pass under way: its share done in [0, 1] and its name ("1/8 size"), or -1 when
    // none is. Whether the last finished pass is the full one.
    std::pair<double, std::string> progress() const;
    bool complete() const;
    // How long the last full pass took, in milliseconds (0 before the first).
    double fullMs() const;

private:
    void run(RenderFn render, RenderSettings full);

    mutable std::mutex mutex_;
    std::thread thread_;
    RenderControl control_;
    Image ready_;
    bool fresh_ = false, busy_ = false, complete_ = false;
    std::string pass_;
    double fullMs_ = 0.0;
    std::exception_ptr error_;
};

}  // namespace boxes
