#include "06_raster/raster.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include "core/exercise.hpp"

namespace boxes {

// EXERCISE 6.1: view and projection matrices from the core's camera (GLM) (2 points)
SpaceMatrices spaceMatrices(const Camera& camera, double near, double far) {
    // BEGIN SOLUTION
    // The camera's own basis, so a view direction parallel to up still gives a finite
    // matrix (the core picks another up then).
    CameraBasisT<float> b = camera.basis();
    glm::dvec3 eye(camera.eye);
    return {glm::lookAt(eye, eye + glm::dvec3(b.forward), glm::dvec3(b.up)),
            glm::perspective(glm::radians(double(camera.fovYDegrees)), double(camera.aspect), near,
                             far)};
    // END SOLUTION
}

Mat4d viewMatrix(const Camera& camera) {
    return spaceMatrices(camera, 1.0, 2.0).view;
}

Mat4d projectionMatrix(const Camera& camera, double near, double far) {
    return spaceMatrices(camera, near, far).projection;
}

// EXERCISE 6.2: clip space to screen: divide by w, viewport, row 0 at the top (1 point)
glm::dvec3 clipToScreen(const Vec4d& clip, int width, int height) {
    // BEGIN SOLUTION
    glm::dvec3 ndc = glm::dvec3(clip) / clip.w;
    return {(ndc.x + 1.0) * 0.5 * double(width), (1.0 - ndc.y) * 0.5 * double(height), ndc.z};
    // END SOLUTION
}

// EXERCISE 6.3: Sutherland-Hodgman: clip a polygon against one plane in clip space (3 points)
ClipPolygon clipAgainstPlane(const ClipPolygon& polygon, const Vec4d& plane) {
    // BEGIN SOLUTION
    ClipPolygon out;
    for (int i = 0; i < polygon.count; ++i) {
        const ClipVertex& a = polygon.vertices[size_t(i)];
        const ClipVertex& b = polygon.vertices[size_t((i + 1) % polygon.count)];
        double da = glm::dot(plane, a.position), db = glm::dot(plane, b.position);
        bool aInside = da >= 0.0, bInside = db >= 0.0;
        if (aInside) out.add(a);
        if (aInside != bInside) {
            // From the inside end to the outside end: the same point for either winding.
            const ClipVertex& in = aInside ? a : b;
            const ClipVertex& outside = aInside ? b : a;
            double dIn = aInside ? da : db, dOut = aInside ? db : da;
            double t = dIn / (dIn - dOut);
            out.add({in.position + t * (outside.position - in.position),
                     in.weights + t * (outside.weights - in.weights)});
        }
    }
    return out;
    // END SOLUTION
}

// EXERCISE 6.4: the edge function (b - a) x (p - a) on fixed-point screen positions (1 point)
int64_t edgeFunction(const FixedPoint2& a, const FixedPoint2& b, const FixedPoint2& p) {
    // BEGIN SOLUTION
    return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
    // END SOLUTION
}

// EXERCISE 6.5: the top-left fill rule: which edges own the pixel centres on them (2 points)
bool isTopLeftEdge(const FixedPoint2& a, const FixedPoint2& b) {
    // BEGIN SOLUTION
    int64_t dx = b.x - a.x, dy = b.y - a.y;
    bool top = dy == 0 && dx > 0;
    bool left = dy < 0;
    return top || left;
    // END SOLUTION
}

// EXERCISE 6.6: the z-buffer's depth test, ties kept by the first triangle drawn (1 point)
bool depthTest(float& stored, float incoming) {
    // BEGIN SOLUTION
    if (!(incoming < stored)) return false;
    stored = incoming;
    return true;
    // END SOLUTION
}

// EXERCISE 6.7: perspective-correct interpolation weights with 1/w (2 points)
glm::dvec3 perspectiveCorrectWeights(const glm::dvec3& screen, const glm::dvec3& w) {
    // BEGIN SOLUTION
    glm::dvec3 q = screen / w;
    return q / (q.x + q.y + q.z);
    // END SOLUTION
}

}  // namespace boxes
