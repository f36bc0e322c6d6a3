// Helpers shared by the test files: running a step program, reading PNG sizes, checking
// numbers against hand-worked values.
#pragma once

#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/math.hpp"
#include "core/render.hpp"

// A failing CHECK on GLM vectors prints them as (x, y, z), every digit that tells two
// values apart, instead of doctest's {?}.
namespace doctest {
template <glm::length_t L, typename T, glm::qualifier Q>
struct StringMaker<glm::vec<L, T, Q>> {
    static String convert(const glm::vec<L, T, Q>& v) {
        std::ostringstream s;
        s.precision(std::numeric_limits<T>::max_digits10);
        s << "(";
        for (glm::length_t i = 0; i < L; ++i) s << (i ? ", " : "") << +v[i];
        s << ")";
        return String(s.str().c_str());
    }
};

namespace detail {
// The hits and intervals the steps return, known by their fields' names: this header
// includes no step's header.
template <typename T>
concept StepResult = requires(const T& y) {
    y.t, y.primitive, y.point;
}
|| requires(const T& y) {
    y.t, y.triangle;
}
|| requires(const T& y) {
    y.t, y.u, y.v;
}
|| requires(const T& y) {
    y.t, y.normal, y.face, y.entering;
}
|| requires(const T& y) {
    y.tnear, y.tfar;
}
|| requires(const T& y) {
    y.normal, y.d;
}
|| requires(const T& y) {
    y.min, y.max;
};
}  // namespace detail

// A failing CHECK on a hit, an interval, a plane or a box prints its fields ("{t = 2, u = 0.2,
// v = 0.3}") instead of {?}.
template <detail::StepResult T>
struct StringMaker<T> {
    static String convert(const T& x) {
        String fields;
        if constexpr (requires { x.t, x.primitive, x.point; })
            fields = "t = " + toString(x.t) + ", primitive " + toString(x.primitive) + " at " +
                     toString(x.point) + ", u = " + toString(x.u) + ", v = " + toString(x.v);
        else if constexpr (requires { x.t, x.triangle; })
            fields = "t = " + toString(x.t) + ", triangle " + toString(x.triangle);
        else if constexpr (requires { x.t, x.u, x.v; })
            fields = "t = " + toString(x.t) + ", u = " + toString(x.u) + ", v = " + toString(x.v);
        else if constexpr (requires { x.t, x.normal, x.face, x.entering; })
            fields = "t = " + toString(x.t) + ", face " + toString(x.face) + ", normal " +
                     toString(x.normal) + (x.entering ? ", entering" : ", leaving");
        else if constexpr (requires { x.tnear, x.tfar; })
            fields = "tnear = " + toString(x.tnear) + ", tfar = " + toString(x.tfar);
        else if constexpr (requires { x.normal, x.d; })
            fields = "normal " + toString(x.normal) + ", d = " + toString(x.d);
        else
            fields = "min " + toString(x.min) + ", max " + toString(x.max);
        return "{" + fields + "}";
    }
};

// A list (the triangles a traversal tested, say) prints its first elements: "{0, 1}".
template <typename T, typename A>
struct StringMaker<std::vector<T, A>> {
    static String convert(const std::vector<T, A>& v) {
        constexpr size_t kShown = 20;
        String s = "{";
        for (size_t i = 0; i < v.size() && i < kShown; ++i) s += (i ? ", " : "") + toString(v[i]);
        if (v.size() > kShown) s += ", ... (" + toString(v.size()) + " in all)";
        return s + "}";
    }
};

// A result that may be absent says which: "nullopt", or its value.
template <typename T>
struct StringMaker<std::optional<T>> {
    static String convert(const std::optional<T>& v) {
        return v ? toString(*v) : String("nullopt");
    }
};
}  // namespace doctest

namespace boxes::test {

// The tree's data/ (test_main.cpp) and, in a step's test program, the step's program (a file
// tests/CMakeLists.txt generates): paths outside the test files, which compile the same in
// every tree.
std::string dataDir();
std::string stepProgram();

// A fresh folder under the system's temporary directory, removed at scope exit.
struct TempDir {
    std::filesystem::path path;
    TempDir() {
        std::string pattern =
            (std::filesystem::temp_directory_path() / "boxes-test-XXXXXX").string();
        path = mkdtemp(pattern.data());
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path, ec);
    }
    std::string file(const std::string& name) const { return (path / name).string(); }
};

inline std::string readText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// Environment for scripted window runs: SDL's offscreen driver (EGL on Mesa, no display).
// Mesa's drivers leave allocations behind when they are unloaded at exit, which
// LeakSanitizer reports from "unknown modules": leak checks are off for these runs only.
constexpr const char* kWindowEnvironment = "SDL_VIDEODRIVER=offscreen ASAN_OPTIONS=detect_leaks=0";

struct ProgramRun {
    int exitCode = -1;
    std::string out, err;
};

// Runs `program args` in `dir` with extra environment assignments ("A=1 B=2").
inline ProgramRun runProgram(const std::string& program, const std::string& args,
                             const TempDir& dir, const std::string& env = "") {
    std::string out = dir.file("stdout.txt"), err = dir.file("stderr.txt");
    std::string cmd = "cd '" + dir.path.string() + "' && env " + env + " '" + program + "' " +
                      args + " >'" + out + "' 2>'" + err + "' </dev/null";
    int status = std::system(cmd.c_str());
    ProgramRun run;
    run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    run.out = readText(out);
    run.err = readText(err);
    return run;
}

inline size_t lineCount(const std::string& s) {
    size_t n = 0;
    for (char c : s) n += c == '\n';
    return n + (!s.empty() && s.back() != '\n');
}

// Width and height from a PNG file's IHDR chunk; (0, 0) when it is not a PNG.
inline std::pair<int, int> pngSize(const std::string& path) {
    std::string bytes = readText(path);
    if (bytes.size() < 24 || bytes.compare(1, 3, "PNG") != 0) return {0, 0};
    auto be32 = [&](size_t i) {
        return int((uint8_t(bytes[i]) << 24) | (uint8_t(bytes[i + 1]) << 16) |
                   (uint8_t(bytes[i + 2]) << 8) | uint8_t(bytes[i + 3]));
    };
    return {be32(16), be32(20)};
}

// ---- The "program NN" suites: the checks every step program's runs share ---------------

// `program --headless --width W --height H --out a.png args` in dir: exits 0 and writes
// a.png of W x H (its stderr shown when not).
inline ProgramRun runHeadless(const std::string& program, const TempDir& dir, int width, int height,
                              const std::string& args = "") {
    auto run = runProgram(program,
                          "--headless --width " + std::to_string(width) + " --height " +
                              std::to_string(height) + " --out a.png " + args,
                          dir);
    INFO(run.err);
    REQUIRE(run.exitCode == 0);
    CHECK(pngSize(dir.file("a.png")) == std::pair{width, height});
    return run;
}

// The JSON report at `path` has every table id ("triangle_speed": the quoted key).
inline void checkReportTables(const std::string& path, std::initializer_list<const char*> ids) {
    std::string json = readText(path);
    for (const char* id : ids) {
        INFO(std::string(id));
        CHECK(json.find(std::string("\"") + id + "\"") != std::string::npos);
    }
}

// Tables of variants in a step's JSON report: each names a time column with its spread
// (low, high) and an error column, all among its columns, states its reference in its
// note, and every row has numbers there with low <= median <= high. The problems found,
// one line each (none: the tables are sound); a table showing only its time or only its
// error is one.
inline std::vector<std::string> variantTableProblems(const nlohmann::json& report,
                                                     const std::vector<std::string>& ids) {
    std::vector<std::string> problems;
    for (const std::string& id : ids) {
        const nlohmann::json* table = nullptr;
        if (report.contains("tables"))
            for (const auto& t : report["tables"])
                if (t.value("id", "") == id) table = &t;
        if (!table) {
            problems.push_back(id + ": no such table");
            continue;
        }
        const auto& t = *table;
        const bool hasTime = t.contains("time") && t["time"].is_object(),
                   hasError = t.contains("error") && t["error"].is_string();
        if (!hasTime) problems.push_back(id + ": no time column");
        if (!hasError) problems.push_back(id + ": no error column");
        if (!hasTime || !hasError) continue;
        const nlohmann::json columns = t.value("columns", nlohmann::json::array());
        auto index = [&](const nlohmann::json& name) -> std::optional<size_t> {
            for (size_t i = 0; i < columns.size(); ++i)
                if (columns[i] == name) return i;
            problems.push_back(id + ": no column " + name.dump());
            return std::nullopt;
        };
        const auto& time = t["time"];
        auto median = index(time.value("median", "")), low = index(time.value("low", "")),
             high = index(time.value("high", "")), error = index(t["error"]);
        if (!median || !low || !high || !error) continue;
        if (t.value("note", "").empty()) problems.push_back(id + ": no note stating the reference");
        const nlohmann::json rows = t.value("rows", nlohmann::json::array());
        if (rows.empty()) problems.push_back(id + ": no rows");
        for (const auto& row : rows) {
            auto number = [&](size_t i) { return i < row.size() && row[i].is_number(); };
            if (!number(*median) || !number(*low) || !number(*high) || !number(*error)) {
                problems.push_back(id + ": a row without its time or error: " + row.dump());
                continue;
            }
            double lo = row[*low].get<double>(), mid = row[*median].get<double>(),
                   hi = row[*high].get<double>();
            if (!(lo <= mid && mid <= hi))
                problems.push_back(id +
                                   ": a row with its median outside its spread: " + row.dump());
        }
    }
    return problems;
}

inline void checkVariantTables(const std::string& path, std::initializer_list<const char*> ids) {
    nlohmann::json report = nlohmann::json::parse(readText(path));
    for (const std::string& problem :
         variantTableProblems(report, std::vector<std::string>(ids.begin(), ids.end())))
        FAIL_CHECK(problem);
}

// The step's picture in a JSON report: a plot with "pareto": true of a table of variants,
// its time column on x and its error column on y, as the report and the deck draw it.
inline void checkParetoPlot(const std::string& path, const std::string& tableId) {
    nlohmann::json report = nlohmann::json::parse(readText(path));
    const nlohmann::json* table = nullptr;
    for (const auto& t : report["tables"])
        if (t["id"] == tableId) table = &t;
    REQUIRE(table != nullptr);
    REQUIRE(table->contains("time"));
    REQUIRE(table->contains("error"));
    bool found = false;
    for (const auto& p : report["plots"])
        found = found || (p.value("pareto", false) && p["table"] == tableId &&
                          p["x"] == (*table)["time"]["median"] && p["y"] == (*table)["error"]);
    CHECK(found);
}

// `program args --frames N --keys K --screenshot shot.png` under the offscreen video
// driver: exits 0 and saves a non-empty screenshot of the last frame.
inline ProgramRun runWindowScript(const std::string& program, const TempDir& dir,
                                  const std::string& args, int frames, const std::string& keys) {
    auto run = runProgram(
        program,
        args + " --frames " + std::to_string(frames) + " --keys " + keys + " --screenshot shot.png",
        dir, kWindowEnvironment);
    INFO(run.err);
    REQUIRE(run.exitCode == 0);
    CHECK(pngSize(dir.file("shot.png")).first > 0);
    return run;
}

// Bad input: `program prefix args` exits with `code`, writes one line on stderr that
// contains `expect`, and leaves none of `outputs` behind in dir.
struct BadInput {
    std::string args, expect;
    int code;
};
inline void checkBadInput(const std::string& program, const TempDir& dir,
                          const std::vector<BadInput>& cases,
                          const std::string& prefix = "--headless --out bad.png ",
                          std::initializer_list<const char*> outputs = {"bad.png"}) {
    for (const BadInput& c : cases) {
        INFO(c.args);
        auto run = runProgram(program, prefix + c.args, dir);
        CHECK(run.exitCode == c.code);
        CHECK(lineCount(run.err) == 1);
        CHECK(run.err.find(c.expect) != std::string::npos);
        for (const char* output : outputs) CHECK_FALSE(std::filesystem::exists(dir.file(output)));
    }
}

// Every component within an absolute tolerance.
template <typename A, typename B>
void checkVec(const A& actual, const B& expected, double tolerance) {
    for (int i = 0; i < 3; ++i) {
        INFO("component " << i << " of " << actual << ": got " << double(actual[i]) << ", expected "
                          << double(expected[i]) << " (of " << expected << ")");
        CHECK(std::abs(double(actual[i]) - double(expected[i])) <= tolerance);
    }
}

// Renders a scene once with the renderer's analysis and once with every effect forced on
// (effects on demand must not change the image): the images must be identical, the ray
// counts may differ.
struct EffectsComparison {
    RayCounts lean, forced;
    bool identical = false;
};
inline EffectsComparison renderBothWays(const Scene& scene, int width, int height,
                                        int maxDepth = 5) {
    RenderSettings s;
    s.width = width;
    s.height = height;
    s.maxDepth = maxDepth;
    EffectsComparison c;
    Image a = renderImage(scene, scene.camera, s, &c.lean);
    s.forceAllEffects = true;
    Image b = renderImage(scene, scene.camera, s, &c.forced);
    c.identical = a.pixels() == b.pixels();
    return c;
}

}  // namespace boxes::test

#include <fenv.h>

namespace boxes::test {

// Turns floating-point traps off for a scope: for code that produces a NaN on purpose
// (say why at the use). Without BOXES_FP_TRAPS=1 it changes nothing.
struct FpTrapsOff {
    int saved = fegetexcept();
    FpTrapsOff() { fedisableexcept(FE_ALL_EXCEPT); }
    ~FpTrapsOff() {
        feclearexcept(FE_ALL_EXCEPT);
        feenableexcept(saved);
    }
};

}  // namespace boxes::test
