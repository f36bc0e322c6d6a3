// Writes the differential tests' data: the reference's answers on each exercise's generated
// inputs (harness.hpp). Run from the reference tree by `./workbook differential`; in a
// starter kit it would write the stubs' answers, so the command refuses to run there.
//
//   differential_data --write DIR [--seed S] [NAME ...]   DIR/NAME.txt (the shipped sets: seed 1)
//   differential_data --check DIR                         the shipped sets are this tree's answers
//   differential_data --hidden DIR --seed S               DIR/stepNN_differential_hidden.cpp
//   differential_data --show NAME [--seed S]              each input, its family and answer
//   differential_data --list                              the data sets
// doctest's own functions (the harness's checks are compiled, never run, here).
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "differential/step01.hpp"
#include "differential/step02.hpp"
#include "differential/step03.hpp"
#include "differential/step04.hpp"
#include "differential/step05.hpp"
#include "differential/step06.hpp"

using namespace boxes::differential;

namespace {

struct DataSet {
    std::string name, exercise, type;
    int step;
    std::string (*generate)(uint64_t);
    std::string (*explain)(uint64_t);
};

std::vector<DataSet> dataSets() {
    std::vector<DataSet> all;
#define BOXES_ENTRY(SPEC) \
    all.push_back({SPEC::name, SPEC::exercise, #SPEC, kStep, &generate<SPEC>, &explain<SPEC>});
    {
        constexpr int kStep = 1;
        BOXES_DIFFERENTIAL_STEP01(BOXES_ENTRY)
    }
    {
        constexpr int kStep = 2;
        BOXES_DIFFERENTIAL_STEP02(BOXES_ENTRY)
    }
    {
        constexpr int kStep = 3;
        BOXES_DIFFERENTIAL_STEP03(BOXES_ENTRY)
    }
    {
        constexpr int kStep = 4;
        BOXES_DIFFERENTIAL_STEP04(BOXES_ENTRY)
    }
    {
        constexpr int kStep = 5;
        BOXES_DIFFERENTIAL_STEP05(BOXES_ENTRY)
    }
    {
        constexpr int kStep = 6;
        BOXES_DIFFERENTIAL_STEP06(BOXES_ENTRY)
    }
#undef BOXES_ENTRY
    return all;
}

bool writeFile(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
    out.close();
    if (!out) std::cerr << "differential_data: cannot write " << path << "\n";
    return bool(out);
}

// A doctest file with the sets of one step for `seed`, each in its exercise's suite: what
// `./workbook grade --hidden DIR` compiles into the step's test program.
std::string hiddenFile(int step, const std::vector<DataSet>& sets, uint64_t seed) {
    char header[32];
    std::snprintf(header, sizeof header, "differential/step%02d.hpp", step);
    std::string out =
        "// Hidden differential sets: the reference's answers on inputs generated with seed " +
        std::to_string(seed) +
        ",\n// written by ./workbook differential --hidden. Not for students.\n" + "#include \"" +
        header + "\"\n\nnamespace {\n";
    for (size_t i = 0; i < sets.size(); ++i)
        out += "const char* const kData" + std::to_string(i) + " = R\"boxes(" +
               sets[i].generate(seed) + ")boxes\";\n";
    out += "}  // namespace\n";
    for (size_t i = 0; i < sets.size(); ++i)
        out += "\nTEST_SUITE(\"exercise " + sets[i].exercise +
               "\") {\n    TEST_CASE(\"hidden generated inputs: " + sets[i].name +
               " as the reference answers\") {\n        "
               "boxes::differential::check<boxes::differential::" +
               sets[i].type + ">(kData" + std::to_string(i) + ");\n    }\n}\n";
    return out;
}

int usage() {
    std::cerr
        << "usage: differential_data --write DIR [--seed S] [NAME ...] | --hidden DIR --seed S | "
           "--show NAME [--seed S] | --list\n";
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> args(argv + 1, argv + argc);
    std::string mode, dir;
    uint64_t seed = 1;
    bool seedGiven = false;
    std::vector<std::string> names;
    for (size_t i = 0; i < args.size(); ++i) {
        if ((args[i] == "--write" || args[i] == "--hidden" || args[i] == "--check") &&
            i + 1 < args.size()) {
            mode = args[i];
            dir = args[++i];
        } else if (args[i] == "--seed" && i + 1 < args.size()) {
            const std::string& s = args[++i];
            auto r = std::from_chars(s.data(), s.data() + s.size(), seed);
            if (r.ec != std::errc() || r.ptr != s.data() + s.size()) {
                std::cerr << "differential_data: --seed: '" << s << "' is not a decimal integer\n";
                return 2;
            }
            seedGiven = true;
        } else if (args[i] == "--show") {
            mode = "--show";
        } else if (args[i] == "--list") {
            mode = "--list";
        } else if (!args[i].empty() && args[i][0] != '-') {
            names.push_back(args[i]);
        } else {
            return usage();
        }
    }
    auto sets = dataSets();
    if (mode == "--list") {
        for (const auto& s : sets) std::cout << s.name << " " << s.exercise << "\n";
        return 0;
    }
    if (mode == "--show") {
        for (const auto& s : sets)
            for (const auto& n : names)
                if (n == s.name) std::cout << s.explain(seed);
        return 0;
    }
    if (mode == "--write") {
        int written = 0;
        for (const auto& s : sets) {
            bool wanted = names.empty();
            for (const auto& n : names) wanted = wanted || n == s.name || n == s.exercise;
            if (!wanted) continue;
            if (!writeFile(dir + "/" + s.name + ".txt", s.generate(seed))) return 1;
            ++written;
        }
        if (!written) {
            std::cerr << "differential_data: no data set named that (--list)\n";
            return 2;
        }
        return 0;
    }
    if (mode == "--check") {
        // The tree's reference reproduces every shipped data set, byte for byte: the answers
        // a starter kit's tests compare with are this tree's.
        int stale = 0;
        for (const auto& s : sets) {
            std::ifstream in(dir + "/" + s.name + ".txt", std::ios::binary);
            std::string shipped((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
            std::string made = s.generate(1);
            if (shipped == made) continue;
            ++stale;
            size_t at = 0, line = 1;
            while (at < shipped.size() && at < made.size() && shipped[at] == made[at])
                line += shipped[at++] == '\n';
            std::cerr << "differential_data: " << dir << "/" << s.name
                      << ".txt differs from the reference's answers"
                      << (shipped.empty() ? " (missing)" : " from line " + std::to_string(line))
                      << " (./workbook differential --write)\n";
        }
        std::cout << sets.size() - size_t(stale) << " of " << sets.size()
                  << " data sets are the reference's answers\n";
        return stale ? 1 : 0;
    }
    if (mode == "--hidden") {
        if (!seedGiven || seed == 1) {
            std::cerr
                << "differential_data: --hidden needs --seed S other than the shipped sets' 1\n";
            return 2;
        }
        std::error_code ec;
        std::filesystem::create_directories(dir, ec);
        std::map<int, std::vector<DataSet>> bySteps;
        for (const auto& s : sets) bySteps[s.step].push_back(s);
        for (const auto& [step, list] : bySteps) {
            char file[64];
            std::snprintf(file, sizeof file, "/step%02d_differential_hidden.cpp", step);
            if (!writeFile(dir + file, hiddenFile(step, list, seed))) return 1;
        }
        return 0;
    }
    return usage();
}
