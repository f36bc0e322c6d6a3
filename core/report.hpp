// Measurement tables that people read in the terminal and scripts read as JSON.
#pragma once

#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace boxes {

using Cell = std::variant<std::string, double, long long>;

struct Table {
    Table() = default;
    // A table's set-up in one statement: what it is, its columns, how it was measured.
    Table(std::string id, std::string title, std::vector<std::string> columns,
          std::string note = "")
        : id(std::move(id)),
          title(std::move(title)),
          columns(std::move(columns)),
          note(std::move(note)) {}

    std::string id;     // short key for scripts and the report, e.g. "triangle_speed"
    std::string title;  // one line for people
    std::vector<std::string> columns;
    std::vector<std::vector<Cell>> rows;
    std::string note;  // how it was measured, the reference the error is against
    // A table of variants names the columns of its time (the median and the spread, e.g.
    // min and max) and of its error against the reference its note states: the report
    // plots one against the other, and the tests check that no such table shows one side.
    std::string timeColumn, timeLowColumn, timeHighColumn, errorColumn;

    Table& row(std::vector<Cell> cells);
    // Declares the time and error columns (they must be among `columns`).
    Table& timeAndError(std::string median, std::string low, std::string high, std::string error);
    void print(std::ostream& out) const;
    nlohmann::json toJson() const;
};

// Everything a program measured in one run: its tables, images written, and facts.
struct Report {
    std::string program;  // e.g. "01_triangle"
    std::vector<Table> tables;
    std::vector<std::pair<std::string, std::string>> images;  // (path, caption)
    nlohmann::json facts = nlohmann::json::object();
    // Plots the report page draws from the tables: {"table", "x", "y", "series" (a column
    // that names the points or lines), "title", "logx", "logy"}.
    nlohmann::json plots = nlohmann::json::array();

    Table& add(Table table);
    nlohmann::json toJson() const;
    // Human tables to `out`; when jsonPath is not empty, also the JSON there ("-": stdout).
    void write(std::ostream& out, const std::string& jsonPath) const;
};

// Formats a timing as "12.3 ns" style text for tables.
std::string formatSeconds(double seconds);
// The machine's name for measurements (CPU model and core count).
std::string machineDescription();

}  // namespace boxes
