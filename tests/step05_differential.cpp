// Step 05's exercises against the reference's answers on generated inputs
// (tests/differential/harness.hpp): random ones and the hard-case families.
#include "differential/step05.hpp"

using namespace boxes::differential;

TEST_SUITE("exercise 5.1") {
    TEST_CASE("generated inputs: the sine table as the reference's") {
        checkShipped<FillSinTableSpec>();
    }
}

TEST_SUITE("exercise 5.2") {
    TEST_CASE("generated inputs: the nearest table entry as the reference's") {
        checkShipped<SinNearestSpec>();
    }
}

TEST_SUITE("exercise 5.3") {
    TEST_CASE("generated inputs: the interpolated sine as the reference's") {
        checkShipped<SinInterpolatedSpec>();
    }
}

TEST_SUITE("exercise 5.4") {
    TEST_CASE("generated inputs: the any-hit loop and its counter as the reference's") {
        checkShipped<EarlyOutSpec>();
    }
}

TEST_SUITE("exercise 5.5") {
    TEST_CASE("generated inputs: the light's finite radius as the reference's") {
        checkShipped<LightRadiusSpec>();
    }
}

TEST_SUITE("exercise 5.6") {
    TEST_CASE("generated inputs: the reciprocal slab test as the reference's") {
        checkShipped<ReciprocalSlabSpec>();
    }
}

TEST_SUITE("exercise 5.7") {
    TEST_CASE("generated inputs: Moller-Trumbore on precomputed edges as the reference's") {
        checkShipped<PrecomputedTriangleSpec>();
    }
}

TEST_SUITE("exercise 5.8") {
    TEST_CASE("generated inputs: the approximate inverse square root as the reference's") {
        checkShipped<InverseSqrtSpec>();
    }
}

TEST_SUITE("exercise 5.9") {
    TEST_CASE("generated inputs: the lines rendered within each budget as the reference's") {
        checkShipped<RefineSpec>();
    }
}

TEST_SUITE("exercise 5.10") {
    TEST_CASE("generated inputs: the adaptive resolution scale as the reference's") {
        checkShipped<AdaptiveSpec>();
    }
}
