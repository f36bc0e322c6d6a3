// Step 01's exercises against the reference's answers on generated inputs
// (tests/differential/harness.hpp): random ones and the hard-case families.
#include "differential/step01.hpp"

using namespace boxes::differential;

TEST_SUITE("exercise 1.1") {
    TEST_CASE("generated inputs: the triangle's plane in float as the reference's") {
        checkShipped<TrianglePlaneFloat>();
    }
    TEST_CASE("generated inputs: the triangle's plane in double as the reference's") {
        checkShipped<TrianglePlaneDouble>();
    }
}

TEST_SUITE("exercise 1.2") {
    TEST_CASE("generated inputs: the ray/plane distance in float as the reference's") {
        checkShipped<RayPlaneDistanceFloat>();
    }
    TEST_CASE("generated inputs: the ray/plane distance in double as the reference's") {
        checkShipped<RayPlaneDistanceDouble>();
    }
}

TEST_SUITE("exercise 1.3") {
    TEST_CASE("generated inputs: the inside test in float as the reference's") {
        checkShipped<InsideEdgePlanesFloat>();
    }
    TEST_CASE("generated inputs: the inside test in double as the reference's") {
        checkShipped<InsideEdgePlanesDouble>();
    }
}

TEST_SUITE("exercise 1.4") {
    TEST_CASE("generated inputs: Moller-Trumbore in float as the reference's") {
        checkShipped<MollerTrumboreFloat>();
    }
    TEST_CASE("generated inputs: Moller-Trumbore in double as the reference's") {
        checkShipped<MollerTrumboreDouble>();
    }
}

TEST_SUITE("exercise 1.5") {
    TEST_CASE("generated inputs: the watertight test in float as the reference's") {
        checkShipped<WatertightFloat>();
    }
    TEST_CASE("generated inputs: the watertight test in double as the reference's") {
        checkShipped<WatertightDouble>();
    }
}

TEST_SUITE("exercise 1.6") {
    TEST_CASE("generated inputs: the interpolated normal as the reference's") {
        checkShipped<InterpolateNormalSpec>();
    }
}
