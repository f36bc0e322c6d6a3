// The interactive half of the program shell: an SDL2 window (OpenGL 3.3 core context)
// that shows the step's image scaled to the window, with a Dear ImGui panel listing the
// keys, the frame time, the progress of a render and the step's own status lines. The
// panel stands beside the picture (never over it) unless moved over it (F2), and folds to
// one line (F1). Works under Xvfb, a real display, or SDL_VIDEODRIVER=offscreen (EGL on
// Mesa) for CI.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "core/image.hpp"

namespace boxes {

struct KeyBinding {
    int key = 0;              // an SDL_Keycode, e.g. SDLK_t
    std::string description;  // shown on screen and in --help, e.g. "switch triangle test"
};

// Where the panel stands: in a column beside the picture (the picture is scaled into the
// rest of the window), or over the picture's top-left corner; folded to one line or not.
struct PanelPlacement {
    bool beside = true;
    bool folded = false;
};

struct WindowOptions {
    std::string title = "Boxes";
    PanelPlacement panel;
    int width = 960;  // window size in screen pixels; the image is scaled to fit
    int height = 720;
    // Scripted runs for tests and CI: stop after this many frames (0: run until closed),
    // pressing scriptedKeys[i] (SDL key names such as "t", "Space", "F1") before frame i+1.
    int scriptedFrames = 0;
    std::vector<std::string> scriptedKeys;
    // When not empty, the last frame (image and panel) is saved here as a PNG.
    std::string screenshotPath;
};

struct WindowCallbacks {
    std::vector<KeyBinding> keys;
    // Called for every key press (also key repeats). Return true when the key was used.
    std::function<bool(int key)> onKey;
    // Called while a mouse button is held and the mouse moves, in screen pixels.
    std::function<void(float dx, float dy)> onMouseDrag;
    // Called once per frame before drawing: produce or update the image to show.
    // The argument is the time in seconds since the previous frame.
    std::function<const Image&(double dt)> frame;
    // Extra ImGui widgets/text for the panel (called inside the panel's Begin/End).
    std::function<void()> panel;
    // A render under way: its progress in [0, 1] and what it is (e.g. "refining 1/4"), or
    // a negative progress when none is. Shown in the panel and on its folded line.
    std::function<std::pair<double, std::string>()> progress;
    // The window is closing (Escape, Q, its close button, or the scripted frames done): stop
    // what runs beside it, before the window goes.
    std::function<void()> onClose;
};

// The keys the window itself answers (listed in the panel after the step's).
constexpr int kPanelFoldKey = 0x4000003A;  // SDLK_F1: the panel folds to one line and back
constexpr int kPanelMoveKey = 0x4000003B;  // SDLK_F2: the panel beside / over the picture

// Runs the window loop until the window is closed, the scripted frames are done, or
// Escape or Q is pressed and onKey did not use it (so a step may use Escape to cancel).
// Throws std::runtime_error with a one-line reason when no window can be opened (no
// display, no OpenGL 3.3).
void runWindow(const WindowOptions& options, WindowCallbacks& callbacks);

}  // namespace boxes
