// The lecture's ladder of expensive operations (sin, cos; sqrt; /; *; +, -) as a run of step
// 05 measured it (table op_cost), and its tip on look-up tables against std::sin (table
// sincos): the student's own run when its report is there, else one reference run.
#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "exam/kinds.hpp"

namespace boxes::exam {

const MeasuredCosts& referenceCosts() {
    // One run of `05_efficiency --measure` on a 2-thread x86-64 machine shared with other
    // builds: table op_cost's median ns per operation, table sincos's fastest samples.
    static const MeasuredCosts costs = {"one reference run of step 05 on a 2-thread x86-64 machine",
                                        {{"sin", "float", 5.62},
                                         {"sin", "double", 8.99},
                                         {"cos", "float", 5.97},
                                         {"cos", "double", 11.90},
                                         {"sqrt", "float", 4.17},
                                         {"sqrt", "double", 5.67},
                                         {"/", "float", 3.32},
                                         {"/", "double", 3.69},
                                         {"*", "float", 1.07},
                                         {"*", "double", 0.846},
                                         {"+", "float", 0.773},
                                         {"+", "double", 0.563},
                                         {"-", "float", 0.620},
                                         {"-", "double", 0.564}},
                                        3.38,
                                        3.51};
    return costs;
}

namespace {

const nlohmann::json& table(const nlohmann::json& report, const std::string& id,
                            const std::string& path) {
    if (!report.contains("tables") || !report["tables"].is_array())
        throw std::runtime_error(path + " has no tables: not a step report");
    for (const auto& t : report["tables"])
        if (t.value("id", "") == id) return t;
    throw std::runtime_error(path + " has no table '" + id +
                             "' (it is step 05's report with --measure)");
}

size_t column(const nlohmann::json& t, const std::string& name, const std::string& path) {
    const auto& columns = t.at("columns");
    for (size_t i = 0; i < columns.size(); ++i)
        if (columns[i] == name) return i;
    throw std::runtime_error(path + ": table '" + t.value("id", "") + "' has no column '" + name +
                             "'");
}

}  // namespace

MeasuredCosts readMeasuredCosts(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot read '" + path + "'");
    nlohmann::json report;
    try {
        report = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        throw std::runtime_error(path + " is not JSON (" + e.what() + ")");
    }
    MeasuredCosts costs;
    costs.source = "your run of step 05 (" + path + ")";
    try {
        const auto& ops = table(report, "op_cost", path);
        size_t op = column(ops, "operation", path), type = column(ops, "type", path),
               ns = column(ops, "ns/op", path);
        for (const auto& row : ops.at("rows"))
            costs.ops.push_back({row.at(op).get<std::string>(), row.at(type).get<std::string>(),
                                 row.at(ns).get<double>()});
        // The sine table against std::sin by their fastest samples: a busy machine moves
        // the medians of these short calls by a factor of several.
        const auto& sines = table(report, "sincos", path);
        size_t variant = column(sines, "variant", path), call = column(sines, "min ns", path);
        for (const auto& row : sines.at("rows")) {
            std::string name = row.at(variant).get<std::string>();
            if (name == "table nearest 3600") costs.tableNs = row.at(call).get<double>();
            if (name == "std::sin float") costs.stdSinNs = row.at(call).get<double>();
        }
    } catch (const nlohmann::json::exception& e) {
        throw std::runtime_error(path + ": unexpected table contents (" + e.what() + ")");
    }
    if (costs.ops.empty() || costs.tableNs <= 0.0 || costs.stdSinNs <= 0.0)
        throw std::runtime_error(path + " lacks the rows op_cost and sincos need");
    return costs;
}

namespace gen {

// Operations whose measured times differ by at least this factor pairwise: an order a run
// shows clearly, not one the noise decides.
constexpr double kClearFactor = 1.25;

Question costOrder(Rng& rng, Question q, const MeasuredCosts& costs) {
    std::string type = rng.chance(50) ? "float" : "double";
    std::vector<OpCost> ops;
    for (const OpCost& c : costs.ops)
        if (c.type == type && c.ns > 0.0) ops.push_back(c);
    if (ops.size() < 2) throw std::runtime_error("the measured costs have no " + type + " rows");
    // Four (else three, else two) operations, each pair clearly apart in this run.
    std::vector<OpCost> chosen;
    for (size_t want = std::min<size_t>(4, ops.size()); want >= 2 && chosen.empty(); --want)
        for (int attempt = 0; attempt < 200; ++attempt) {
            std::vector<OpCost> pick = ops;
            rng.shuffle(pick);
            pick.resize(want);
            std::sort(pick.begin(), pick.end(),
                      [](const OpCost& a, const OpCost& b) { return a.ns < b.ns; });
            bool clear = true;
            for (size_t i = 1; i < pick.size(); ++i)
                clear = clear && pick[i].ns >= kClearFactor * pick[i - 1].ns;
            if (clear) {
                chosen = pick;
                break;
            }
        }
    if (chosen.empty()) {  // every pair within the factor: ask the two extremes
        std::sort(ops.begin(), ops.end(),
                  [](const OpCost& a, const OpCost& b) { return a.ns < b.ns; });
        chosen = {ops.front(), ops.back()};
    }
    std::vector<size_t> shown(chosen.size());
    for (size_t i = 0; i < shown.size(); ++i) shown[i] = i;
    rng.shuffle(shown);  // shown[k]: which of the cheapest-first ops gets letter k
    std::string listed, order(chosen.size(), ' ');
    for (size_t k = 0; k < shown.size(); ++k) {
        listed += std::string("\n  ") + char('a' + k) + ") " + chosen[shown[k]].op;
        order[shown[k]] = char('a' + k);
        q.given[std::string(1, char('a' + k))] = {chosen[shown[k]].ns};
    }
    q.given["table"] = {costs.tableNs};
    q.given["std::sin"] = {costs.stdSinNs};
    q.statement =
        "Step 05's table op_cost times each operation of the lecture's list of "
        "expensive operations in a dependent chain (x = op(x): its latency). The "
        "figures come from " +
        costs.source + ". In " + type +
        ", order these from the cheapest to the most expensive as that run measured "
        "them:" +
        listed;
    Part p;
    p.prompt = "the letters from the cheapest to the most expensive, e.g. 'b a c'";
    p.type = AnswerType::Order;
    p.order = order;
    for (size_t i = 0; i < order.size(); ++i) p.shown += (i ? " " : "") + std::string(1, order[i]);
    q.parts.push_back(p);
    bool muchFaster = 2.0 * costs.tableNs <= costs.stdSinNs;
    q.parts.push_back(
        yesNoPart("in the same run (table sincos, the fastest samples), was the nearest entry of a "
                  "3600-entry sine table at least twice as fast as std::sin in float?",
                  muchFaster));
    std::string ladder;
    for (size_t i = 0; i < chosen.size(); ++i)
        ladder += (i ? " < " : "") + chosen[i].op + " " + num(chosen[i].ns) + " ns";
    q.solution = {
        "measured, cheapest first: " + ladder + " (answer: " + p.shown + ")",
        "the lecture lists, most expensive first: sin, cos; sqrt; /; *; +, -. A run shows "
        "that order where the times are clearly apart; + and - cost the same, * little more, "
        "and a division or a square root a few additions, not hundreds",
        "sine table (nearest entry, 3600 entries) " + num(costs.tableNs) + " ns against std::sin " +
            num(costs.stdSinNs) + " ns: " +
            (muchFaster ? "the table was at least twice as fast in this run"
                        : "not twice as fast: the lecture's tip that a look-up table is often "
                          "much faster does not hold here, and the table costs accuracy")};
    return q;
}

}  // namespace gen

}  // namespace boxes::exam
