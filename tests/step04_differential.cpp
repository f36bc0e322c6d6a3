// Step 04's exercises against the reference's answers on generated inputs
// (tests/differential/harness.hpp): random ones and the hard-case families.
#include "differential/step04.hpp"

using namespace boxes::differential;

TEST_SUITE("exercise 4.1") {
    TEST_CASE("generated inputs: the midpoint split as the reference's") {
        checkShipped<MidpointSpec>();
    }
}

TEST_SUITE("exercise 4.2") {
    TEST_CASE("generated inputs: the object median split as the reference's") {
        checkShipped<MedianSpec>();
    }
}

TEST_SUITE("exercise 4.3") {
    TEST_CASE("generated inputs: the binned SAH split as the reference's") {
        checkShipped<BinnedSahSpec>();
    }
}

TEST_SUITE("exercise 4.4") {
    TEST_CASE("generated inputs: the nearest-hit traversal as the reference's") {
        checkShipped<NearestHitSpec>();
    }
}

TEST_SUITE("exercise 4.5") {
    TEST_CASE("generated inputs: the any-hit traversal as the reference's") {
        checkShipped<AnyHitSpec>();
    }
}

TEST_SUITE("exercise 4.6") {
    TEST_CASE("generated inputs: the frustum's planes and corners as the reference's") {
        checkShipped<MakeFrustumSpec>();
    }
}

TEST_SUITE("exercise 4.7") {
    TEST_CASE("generated inputs: the p-vertex test as the reference's") {
        checkShipped<CullByPlanesSpec>();
    }
}

TEST_SUITE("exercise 4.8") {
    TEST_CASE("generated inputs: the corners against the box's planes as the reference's") {
        checkShipped<CullByBoxPlanesSpec>();
    }
}
