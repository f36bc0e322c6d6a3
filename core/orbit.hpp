// Moving the camera in a step's window: orbit around the point it looks at (arrow keys or
// mouse drag) and move closer or further (W/S). Shared by every step program.
#pragma once

#include <SDL2/SDL_keycode.h>

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

#include "core/scene.hpp"
#include "core/window.hpp"

namespace boxes {

class OrbitController {
public:
    explicit OrbitController(const Camera& camera) : camera_(camera) {
        target_ = camera.eye + camera.view;
        distance_ = glm::length(camera.view);
        camera_.view = camera.view;
    }

    const Camera& camera() const { return camera_; }

    static std::vector<KeyBinding> keys() {
        return {{SDLK_LEFT, "orbit left (also: drag with the mouse)"},
                {SDLK_RIGHT, "orbit right"},
                {SDLK_UP, "orbit up"},
                {SDLK_DOWN, "orbit down"},
                {SDLK_w, "move closer"},
                {SDLK_s, "move away"}};
    }

    // True when the key moved the camera.
    bool onKey(int key) {
        const float step = glm::radians(5.0f);
        switch (key) {
            case SDLK_LEFT:
                rotate(-step, 0.0f);
                return true;
            case SDLK_RIGHT:
                rotate(step, 0.0f);
                return true;
            case SDLK_UP:
                rotate(0.0f, step);
                return true;
            case SDLK_DOWN:
                rotate(0.0f, -step);
                return true;
            case SDLK_w:
                zoom(0.9f);
                return true;
            case SDLK_s:
                zoom(1.0f / 0.9f);
                return true;
            default:
                return false;
        }
    }
    void onDrag(float dx, float dy) { rotate(dx * 0.005f, -dy * 0.005f); }

    // Adds the orbit to a step's window: its keys after the step's own (set cb.keys and
    // cb.onKey first; a key the step uses never reaches the orbit) and the mouse drag.
    // `moved` runs whenever the camera moved.
    void addTo(WindowCallbacks& cb, std::function<void()> moved) {
        for (const KeyBinding& k : keys()) cb.keys.push_back(k);
        cb.onKey = [stepKeys = cb.onKey, this, moved](int key) {
            if (stepKeys && stepKeys(key)) return true;
            if (!onKey(key)) return false;
            moved();
            return true;
        };
        cb.onMouseDrag = [this, moved](float dx, float dy) {
            onDrag(dx, dy);
            moved();
        };
    }

private:
    void rotate(float yaw, float pitch) {
        CameraBasisT<float> b = camera_.basis();
        Vec3 offset = camera_.eye - target_;
        // Yaw about the camera's up axis, pitch about its right axis (Rodrigues' formula).
        offset = rotateAbout(offset, glm::normalize(camera_.up), yaw);
        offset = rotateAbout(offset, b.right, pitch);
        camera_.eye = target_ + offset;
        camera_.view = target_ - camera_.eye;
    }
    void zoom(float factor) {
        Vec3 offset = (camera_.eye - target_) * factor;
        if (glm::length(offset) < 1e-6f * (1.0f + glm::length(target_))) return;
        camera_.eye = target_ + offset;
        camera_.view = target_ - camera_.eye;
    }
    static Vec3 rotateAbout(Vec3 v, Vec3 axis, float angle) {
        float c = std::cos(angle), s = std::sin(angle);
        return v * c + glm::cross(axis, v) * s + axis * glm::dot(axis, v) * (1.0f - c);
    }

    Camera camera_;
    Vec3 target_;
    float distance_;
};

}  // namespace boxes
