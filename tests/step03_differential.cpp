// Step 03's exercises against the reference's answers on generated inputs
// (tests/differential/harness.hpp): random ones and the hard-case families.
#include "differential/step03.hpp"

using namespace boxes::differential;

TEST_SUITE("exercise 3.1") {
    TEST_CASE("generated inputs: the bounds of a sphere in float as the reference's") {
        checkShipped<SphereBoundsFloat>();
    }
    TEST_CASE("generated inputs: the bounds of a sphere in double as the reference's") {
        checkShipped<SphereBoundsDouble>();
    }
}

TEST_SUITE("exercise 3.2") {
    TEST_CASE("generated inputs: the bounds of a triangle in float as the reference's") {
        checkShipped<TriangleBoundsFloat>();
    }
    TEST_CASE("generated inputs: the bounds of a triangle in double as the reference's") {
        checkShipped<TriangleBoundsDouble>();
    }
}

TEST_SUITE("exercise 3.3") {
    TEST_CASE("generated inputs: the bounds of a mesh as the reference's") {
        checkShipped<MeshBoundsSpec>();
    }
}

TEST_SUITE("exercise 3.4") {
    TEST_CASE("generated inputs: the union of two boxes in float as the reference's") {
        checkShipped<UnionBoundsFloat>();
    }
    TEST_CASE("generated inputs: the union of two boxes in double as the reference's") {
        checkShipped<UnionBoundsDouble>();
    }
}

TEST_SUITE("exercise 3.5") {
    TEST_CASE("generated inputs: the overlap of two boxes in float as the reference's") {
        checkShipped<OverlapsFloat>();
    }
    TEST_CASE("generated inputs: the overlap of two boxes in double as the reference's") {
        checkShipped<OverlapsDouble>();
    }
}

TEST_SUITE("exercise 3.6") {
    TEST_CASE("generated inputs: the robust slab test in float as the reference's") {
        checkShipped<SlabsFloat>();
    }
    TEST_CASE("generated inputs: the robust slab test in double as the reference's") {
        checkShipped<SlabsDouble>();
    }
}

TEST_SUITE("exercise 3.7") {
    TEST_CASE("generated inputs: the conservative slab test in float as the reference's") {
        checkShipped<SlabsConservativeFloat>();
    }
    TEST_CASE("generated inputs: the conservative slab test in double as the reference's") {
        checkShipped<SlabsConservativeDouble>();
    }
}
