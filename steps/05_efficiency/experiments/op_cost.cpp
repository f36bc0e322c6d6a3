// The cost of one operation (sin, cos, sqrt, /, *, +, -) in float and double: a dependent
// chain, each operation waiting for the previous result, so the time per step is the
// operation's latency and the compiler can neither fold nor vectorize it.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "05_efficiency/experiments/lab_helpers.hpp"
#include "05_efficiency/measure.hpp"
#include "core/timing.hpp"

namespace boxes {

using namespace lab;

namespace {

// Read through a volatile, so the compiler does not know the operand and cannot fold the chain.
template <typename T>
T opaque(T v) {
    volatile T x = v;
    return x;
}

// One chain per operation, x -> op(x, c); each stays in a bounded, well-scaled range (sin
// and cos shrink towards their fixed points below 1, sqrt towards 1, / and * by a factor
// close to 1), so no step meets a denormal or an overflow. `step` is a lambda, so the
// chain's loop has the operation inlined, not a call.
template <typename T, typename Step, typename Exact>
OpCost chainCost(const LabOptions& o, const char* op, const char* type, T start, T c, Step step,
                 Exact exact) {
    // The error of one operation: on the chain's own inputs, against the same operation in
    // long double on the same (rounded) input.
    double worst = 0.0;
    T x = start;
    for (long long i = 0, n = o.quick ? 2000 : 20000; i < n; ++i) {
        T y = step(x, c);
        long double e = exact((long double)x, (long double)c);
        worst = std::max(worst, double(std::abs((long double)y - e) / std::abs(e)));
        x = y;
    }
    // Short chains, three times the repeats: a sample is less often cut by another process.
    const long long steps = o.quick ? 2000 : 50000;
    Timing tm = measure(3 * o.repeats, [&] {
        T v = opaque(start), k = opaque(c);
        for (long long i = 0; i < steps; ++i) v = step(v, k);
        keepValue(v);
    });
    double per = 1e9 / double(steps);
    return {op, type, tm.median * per, tm.min * per, tm.max * per, worst};
}

template <typename T>
void typeCosts(const LabOptions& o, const char* type, std::vector<OpCost>& out) {
    using L = long double;
    out.push_back(chainCost(
        o, "sin", type, T(1), T(0), [](T x, T) { return std::sin(x); },
        [](L x, L) { return std::sin(x); }));
    out.push_back(chainCost(
        o, "cos", type, T(1), T(0), [](T x, T) { return std::cos(x); },
        [](L x, L) { return std::cos(x); }));
    out.push_back(chainCost(
        o, "sqrt", type, T(1e6), T(0), [](T x, T) { return std::sqrt(x); },
        [](L x, L) { return std::sqrt(x); }));
    out.push_back(chainCost(
        o, "/", type, T(1), T(1.000001), [](T x, T k) { return x / k; },
        [](L x, L k) { return x / k; }));
    out.push_back(chainCost(
        o, "*", type, T(1), T(0.999999), [](T x, T k) { return x * k; },
        [](L x, L k) { return x * k; }));
    out.push_back(chainCost(
        o, "+", type, T(1), T(0.001), [](T x, T k) { return x + k; },
        [](L x, L k) { return x + k; }));
    out.push_back(chainCost(
        o, "-", type, T(1000), T(0.001), [](T x, T k) { return x - k; },
        [](L x, L k) { return x - k; }));
}

}  // namespace

std::vector<OpCost> measureOpCosts(const LabOptions& o) {
    std::vector<OpCost> out;
    typeCosts<float>(o, "float", out);
    typeCosts<double>(o, "double", out);
    return out;
}

Table measureOpCost(const LabOptions& o) {
    Table t(
        "op_cost",
        "The cost of an operation: ns per sin, cos, sqrt, /, *, +, - in float and double, and "
        "the error of one operation",
        {"operation", "type", "ns/op", "min ns", "max ns", "x addition", "max rel error"},
        "time: a dependent chain x = op(x) (sin, cos, sqrt; x / c, x * c, x + c, x - c with c "
        "unknown to the compiler), so each operation waits for the one before (latency, no "
        "vectorization); 50,000 steps a sample, one thread, median of three times the repeats; x "
        "addition: against + in the same type; "
        "error: the largest relative error of one operation on the chain's inputs against the "
        "same operation in long double on the same input");
    std::vector<OpCost> costs = measureOpCosts(o);
    auto find = [&](const std::string& op, const std::string& type) {
        for (const OpCost& c : costs)
            if (c.op == op && c.type == type) return c;
        throw std::logic_error("op_cost: no " + op + " " + type);
    };
    // Float and double of one operation next to each other, in the primer's order.
    for (const char* op : {"sin", "cos", "sqrt", "/", "*", "+", "-"})
        for (const char* type : {"float", "double"}) {
            OpCost c = find(op, type);
            t.row({c.op, c.type, c.nsMedian, c.nsMin, c.nsMax,
                   c.nsMedian / find("+", type).nsMedian, c.relError});
        }
    t.timeAndError("ns/op", "min ns", "max ns", "max rel error");
    return t;
}

}  // namespace boxes
