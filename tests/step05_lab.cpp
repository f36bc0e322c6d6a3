// Step 05's lab tables: the language kernels under every set of flags and the cost of
// each operation.
#include <cmath>

#include "05_efficiency/language.hpp"
#include "05_efficiency/measure.hpp"
#include "support.hpp"

using namespace boxes;

TEST_SUITE("lab 05") {
    // The same kernel under every set of flags: on rays that hit a unit sphere well inside
    // its outline or miss it well outside, every variant finds the hand-worked
    // t = 5 - sqrt(1 - x^2 - y^2), float within 1e-6 relative (a few float roundings of
    // numbers near 4 and 5), double within 1e-14.
    TEST_CASE("language kernels: every variant finds the worked t in float and double") {
        const auto& variants = language::kernelVariants();
        REQUIRE(variants.size() >= 3);
        CHECK(language::referenceVariant().name == "O2");
        std::vector<double> spheres = {0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -40.0, 0.5};
        std::vector<double> rays, exact;
        for (int i = 0; i < 200; ++i) {
            // Radii 0 to 0.9 (hits) and 1.1 to 2 (misses), all around.
            double r = i < 100 ? 0.9 * i / 99.0 : 1.1 + 0.9 * (i - 100) / 99.0;
            double x = r * std::cos(0.37 * i), y = r * std::sin(0.37 * i);
            for (double v : {x, y, 5.0, 0.0, 0.0, -1.0}) rays.push_back(v);
            // Rays within 0.5 of the axis hit the far sphere too: the near hit is the answer.
            exact.push_back(r <= 1.0 ? 5.0 - std::sqrt(1.0 - r * r) : INFINITY);
        }
        std::vector<float> spheresF(spheres.begin(), spheres.end()),
            raysF(rays.begin(), rays.end());
        for (const auto& v : variants) {
            INFO(v.name << " (" << v.flags << ")");
            CHECK(v.flags.find("-ffast-math") == std::string::npos);
            std::vector<float> tf(200);
            std::vector<double> td(200);
            v.nearestFloat(spheresF.data(), 2, raysF.data(), 200, tf.data());
            v.nearestDouble(spheres.data(), 2, rays.data(), 200, td.data());
            for (size_t i = 0; i < 200; ++i) {
                INFO("ray " << i);
                if (std::isinf(exact[i])) {
                    CHECK(std::isinf(tf[i]));
                    CHECK(std::isinf(td[i]));
                } else {
                    CHECK(std::abs(double(tf[i]) - exact[i]) <= 1e-6 * exact[i]);
                    CHECK(std::abs(td[i] - exact[i]) <= 1e-14 * exact[i]);
                }
            }
        }
    }
    TEST_CASE(
        "language table: every variant in float and double and the double O2 row is the "
        "reference") {
        LabOptions o;
        o.quick = true;
        o.repeats = 1;
        Table t = measureLanguage(o);
        CHECK(t.id == "language");
        const size_t type = 2, error = 7, flipped = 8;
        REQUIRE(t.columns[type] == "type");
        REQUIRE(t.columns[error] == "max rel t error");
        REQUIRE(t.columns[flipped] == "flipped");
        const auto& variants = language::kernelVariants();
        REQUIRE(t.rows.size() == 2 * variants.size());
        for (const auto& v : variants)
            for (const char* ty : {"float", "double"}) {
                INFO(v.name << " " << ty);
                int found = 0;
                for (const auto& row : t.rows)
                    if (std::get<std::string>(row[0]) == v.name &&
                        std::get<std::string>(row[type]) == ty) {
                        ++found;
                        double err = std::get<double>(row[error]);
                        CHECK(std::isfinite(err));
                        // Float against double: within float's rounding of t near 10 and
                        // the field's grazing rays (cancellation in b^2 - c).
                        if (std::string(ty) == "float") CHECK(err < 1e-3);
                        // IEEE double without contraction gives the same bits at every
                        // optimization level; contracted to FMA it differs by roundings.
                        if (std::string(ty) == "double" && v.name != "native+fma") {
                            CHECK(err == 0.0);
                            CHECK(std::get<long long>(row[flipped]) == 0);
                        }
                        if (std::string(ty) == "double" && v.name == "native+fma")
                            CHECK(err < 1e-9);
                    }
                CHECK(found == 1);
            }
    }
    TEST_CASE("op cost: every operation in float and double with a positive finite time") {
        LabOptions o;
        o.quick = true;
        o.repeats = 1;
        std::vector<OpCost> costs = measureOpCosts(o);
        for (const char* op : {"sin", "cos", "sqrt", "/", "*", "+", "-"})
            for (const char* type : {"float", "double"}) {
                INFO(op << " " << type);
                int found = 0;
                for (const OpCost& c : costs)
                    if (c.op == op && c.type == type) {
                        ++found;
                        CHECK(std::isfinite(c.nsMedian));
                        CHECK(c.nsMedian > 0.0);
                        CHECK(c.nsMin <= c.nsMedian);
                        CHECK(c.nsMedian <= c.nsMax);
                        // One operation rounds once (sin and cos within about an ulp): its
                        // relative error is a few units of the type's rounding, 2^-24 or 2^-53.
                        double unit = std::string(type) == "float" ? 0x1p-24 : 0x1p-53;
                        CHECK(c.relError <= 4.0 * unit);
                    }
                CHECK(found == 1);
            }
        // The basic operations are correctly rounded: half an ulp at most.
        for (const OpCost& c : costs)
            if (c.op == "sqrt" || c.op == "/" || c.op == "*" || c.op == "+" || c.op == "-") {
                INFO(c.op << " " << c.type);
                CHECK(c.relError <= (c.type == "float" ? 0x1p-24 : 0x1p-53));
            }
    }
}
