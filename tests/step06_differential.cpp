// Step 06's exercises against the reference's answers on generated inputs
// (tests/differential/harness.hpp): random ones and the hard-case families.
#include "differential/step06.hpp"

using namespace boxes::differential;

TEST_SUITE("exercise 6.1") {
    TEST_CASE("generated inputs: the view and projection matrices as the reference's") {
        checkShipped<SpaceMatricesSpec>();
    }
}

TEST_SUITE("exercise 6.2") {
    TEST_CASE("generated inputs: clip space to the screen as the reference's") {
        checkShipped<ClipToScreenSpec>();
    }
}

TEST_SUITE("exercise 6.3") {
    TEST_CASE("generated inputs: the polygon clipped against a plane as the reference's") {
        checkShipped<ClipPolygonSpec>();
    }
}

TEST_SUITE("exercise 6.4") {
    TEST_CASE("generated inputs: the edge function as the reference's") {
        checkShipped<EdgeFunctionSpec>();
    }
}

TEST_SUITE("exercise 6.5") {
    TEST_CASE("generated inputs: the top-left fill rule as the reference's") {
        checkShipped<TopLeftSpec>();
    }
}

TEST_SUITE("exercise 6.6") {
    TEST_CASE("generated inputs: the depth test as the reference's") {
        checkShipped<DepthTestSpec>();
    }
}

TEST_SUITE("exercise 6.7") {
    TEST_CASE("generated inputs: the perspective-correct weights as the reference's") {
        checkShipped<PerspectiveWeightsSpec>();
    }
}

TEST_SUITE("exercise 6.8") {
    TEST_CASE("generated inputs: the shadow map lookup as the reference's") {
        checkShipped<ShadowMapSpec>();
    }
}

TEST_SUITE("exercise 6.9") {
    TEST_CASE("generated inputs: the hybrid's shadow ray as the reference's") {
        checkShipped<ShadowRaySpec>();
    }
}
