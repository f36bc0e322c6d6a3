#include "core/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "core/image.hpp"

namespace boxes {

Table& Table::row(std::vector<Cell> cells) {
    rows.push_back(std::move(cells));
    return *this;
}

Table& Table::timeAndError(std::string median, std::string low, std::string high,
                           std::string error) {
    for (const std::string* c : {&median, &low, &high, &error})
        if (std::find(columns.begin(), columns.end(), *c) == columns.end())
            throw std::logic_error("table " + id + " has no column '" + *c + "'");
    timeColumn = std::move(median);
    timeLowColumn = std::move(low);
    timeHighColumn = std::move(high);
    errorColumn = std::move(error);
    return *this;
}

namespace {
std::string cellText(const Cell& c) {
    if (auto s = std::get_if<std::string>(&c)) return *s;
    if (auto i = std::get_if<long long>(&c)) return std::to_string(*i);
    double v = std::get<double>(c);
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[64];
    double a = std::abs(v);
    if (v == 0.0)
        std::snprintf(buf, sizeof buf, "0");
    else if (a >= 1e6 || a < 1e-3)
        std::snprintf(buf, sizeof buf, "%.3g", v);
    else if (a >= 100)
        std::snprintf(buf, sizeof buf, "%.1f", v);
    else
        std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

nlohmann::json cellJson(const Cell& c) {
    if (auto s = std::get_if<std::string>(&c)) return *s;
    if (auto i = std::get_if<long long>(&c)) return *i;
    double v = std::get<double>(c);
    if (!std::isfinite(v)) return cellText(c);  // JSON has no inf/nan
    return v;
}
}  // namespace

void Table::print(std::ostream& out) const {
    std::vector<size_t> width(columns.size(), 0);
    for (size_t i = 0; i < columns.size(); ++i) width[i] = columns[i].size();
    for (const auto& r : rows)
        for (size_t i = 0; i < r.size() && i < width.size(); ++i)
            width[i] = std::max(width[i], cellText(r[i]).size());
    out << "\n" << title << "\n";
    auto line = [&](auto get) {
        for (size_t i = 0; i < columns.size(); ++i) {
            std::string s = get(i);
            bool left = i == 0;
            out << (i ? "  " : "  ") << (left ? std::left : std::right) << std::setw(int(width[i]))
                << s;
        }
        out << "\n";
    };
    line([&](size_t i) { return columns[i]; });
    size_t total = 0;
    for (size_t w : width) total += w + 2;
    out << "  " << std::string(total > 2 ? total - 2 : 0, '-') << "\n";
    for (const auto& r : rows) line([&](size_t i) { return i < r.size() ? cellText(r[i]) : ""; });
    if (!note.empty()) out << "  (" << note << ")\n";
}

nlohmann::json Table::toJson() const {
    nlohmann::json j;
    j["id"] = id;
    j["title"] = title;
    j["columns"] = columns;
    j["note"] = note;
    if (!timeColumn.empty())
        j["time"] = {{"median", timeColumn}, {"low", timeLowColumn}, {"high", timeHighColumn}};
    if (!errorColumn.empty()) j["error"] = errorColumn;
    j["rows"] = nlohmann::json::array();
    for (const auto& r : rows) {
        nlohmann::json row = nlohmann::json::array();
        for (const auto& c : r) row.push_back(cellJson(c));
        j["rows"].push_back(row);
    }
    return j;
}

Table& Report::add(Table table) {
    tables.push_back(std::move(table));
    return tables.back();
}

nlohmann::json Report::toJson() const {
    nlohmann::json j;
    j["program"] = program;
    j["machine"] = machineDescription();
    j["tables"] = nlohmann::json::array();
    for (const auto& t : tables) j["tables"].push_back(t.toJson());
    j["images"] = nlohmann::json::array();
    for (const auto& [path, caption] : images)
        j["images"].push_back({{"path", path}, {"caption", caption}});
    j["facts"] = facts;
    j["plots"] = plots;
    return j;
}

void Report::write(std::ostream& out, const std::string& jsonPath) const {
    for (const auto& t : tables) t.print(out);
    if (jsonPath.empty()) return;
    std::string text = toJson().dump(2) + "\n";
    if (jsonPath == "-") {
        std::fwrite(text.data(), 1, text.size(), stdout);
        std::fflush(stdout);
    } else {
        writeFileAtomically(jsonPath, text.data(), text.size());
    }
}

std::string formatSeconds(double s) {
    char buf[64];
    if (s < 1e-6)
        std::snprintf(buf, sizeof buf, "%.2f ns", s * 1e9);
    else if (s < 1e-3)
        std::snprintf(buf, sizeof buf, "%.2f us", s * 1e6);
    else if (s < 1.0)
        std::snprintf(buf, sizeof buf, "%.2f ms", s * 1e3);
    else
        std::snprintf(buf, sizeof buf, "%.2f s", s);
    return buf;
}

std::string machineDescription() {
    std::ifstream cpuinfo("/proc/cpuinfo");
    std::string line, model = "unknown CPU";
    while (std::getline(cpuinfo, line))
        if (line.rfind("model name", 0) == 0) {
            model = line.substr(line.find(':') + 2);
            break;
        }
    return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " threads";
}

}  // namespace boxes
