// Step 02's exercises against the reference's answers on generated inputs
// (tests/differential/harness.hpp): random ones and the hard-case families.
#include "differential/step02.hpp"

using namespace boxes::differential;

TEST_SUITE("exercise 2.1") {
    TEST_CASE("generated inputs: the six face planes in float as the reference's") {
        checkShipped<BoxFacePlanesFloat>();
    }
    TEST_CASE("generated inputs: the six face planes in double as the reference's") {
        checkShipped<BoxFacePlanesDouble>();
    }
}

TEST_SUITE("exercise 2.2") {
    TEST_CASE("generated inputs: the six-plane box test in float as the reference's") {
        checkShipped<SixPlanesFloat>();
    }
    TEST_CASE("generated inputs: the six-plane box test in double as the reference's") {
        checkShipped<SixPlanesDouble>();
    }
}

TEST_SUITE("exercise 2.3") {
    TEST_CASE("generated inputs: the axis-aligned plane distance in float as the reference's") {
        checkShipped<AxisPlaneDistanceFloat>();
    }
    TEST_CASE("generated inputs: the axis-aligned plane distance in double as the reference's") {
        checkShipped<AxisPlaneDistanceDouble>();
    }
}

TEST_SUITE("exercise 2.4") {
    TEST_CASE("generated inputs: the slab method for an oriented box in float as the reference's") {
        checkShipped<BoxSlabsFloat>();
    }
    TEST_CASE(
        "generated inputs: the slab method for an oriented box in double as the reference's") {
        checkShipped<BoxSlabsDouble>();
    }
}
