// Reliability hard cases of the command line: user text quoted on one line, and every
// number on a command line read exactly, in-process and by every step program.
#include <filesystem>
#include <fstream>
#include <sstream>

#include "04_bvh/advanced/rays.hpp"
#include "core/app.hpp"
#include "core/scene.hpp"
#include "reliability_support.hpp"
#include "support.hpp"

using namespace boxes;
using test::triangleThen;

TEST_SUITE("hard cases reliability") {
    TEST_CASE("hard case: user text quoted in an error message stays on one line") {
        auto messageOf = [](auto&& f) {
            try {
                f();
            } catch (const std::exception& e) {
                return std::string(e.what());
            }
            return std::string("(no error)");
        };
        std::string vec = messageOf([] { parseVec3("1\n2,3", "--eye"); });
        CHECK(vec == "--eye: '1\\x0a2' is not a finite number");
        std::string scene = messageOf([] { makeScene("a\nb", SceneOptions{}); });
        CHECK(scene.find('\n') == std::string::npos);
        CHECK(scene.rfind("unknown scene 'a\\x0ab'", 0) == 0);
        CHECK(printable(std::string(100, 'a'), 10) == "aaaaaaaaaa...");
    }
}

// Every number on a command line read exactly. CLI11 reads numbers with strtoll, strtoull
// and strtold in base 0: --seed -1 became 2^64 - 1, an overflowing seed 2^64 - 1, "010"
// octal 8, and nan passed the range checks.
namespace {

std::string usage(std::vector<std::string> args, CommonOptions* out = nullptr) {
    CLI::App app;
    CommonOptions options;
    addCommonOptions(app, options, "bunny");
    args.insert(args.begin(), "program");
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    try {
        parseCommandLine(app, int(argv.size()), argv.data());
    } catch (const UsageError& e) {
        return e.what();
    }
    if (out) *out = options;
    return "(accepted)";
}

}  // namespace

TEST_SUITE("hard cases reliability") {
    TEST_CASE("hard case: flags that overflow or have a fraction or trailing junk are refused") {
        for (const char* flag : {"--width", "--height", "--threads", "--frames", "--seed"}) {
            INFO(flag);
            const std::string f = flag;
            CHECK(usage({f, "99999999999999999999"}) ==
                  f + ": '99999999999999999999' is out of range");
            CHECK(usage({f, "2.5"}) == f + ": '2.5' is not a decimal integer");
            CHECK(usage({f, "64px"}) == f + ": '64px' is not a decimal integer");
            CHECK(usage({f, "0x40"}) == f + ": '0x40' is not a decimal integer");
            CHECK(usage({f, "+64"}) == f + ": '+64' is not a decimal integer");
            CHECK(usage({f, " 64"}) == f + ": ' 64' is not a decimal integer");
        }
        CHECK(usage({"--seed", "-1"}) == "--seed: '-1' is negative (a count or seed is 0 or more)");
        CHECK(usage({"--seed", "18446744073709551616"}) ==
              "--seed: '18446744073709551616' is out of range");
        // Beyond int but within 64 bits: CLI11 refuses what does not fit the flag's type.
        CHECK(usage({"--threads", "4294967297"}).rfind("--threads: ", 0) == 0);
        CHECK(usage({"--width", "4294967297"}).rfind("--width: ", 0) == 0);
        CHECK(usage({"--fov", "1e999"}) == "--fov: '1e999' is out of range");
        CHECK(usage({"--fov", "nan"}) == "--fov: 'nan' is not a finite decimal number");
        CHECK(usage({"--fov", "inf"}) == "--fov: 'inf' is not a finite decimal number");
        CHECK(usage({"--fov", "45deg"}) == "--fov: '45deg' is not a finite decimal number");
        CHECK(usage({"--fov", "0x1p4"}) == "--fov: '0x1p4' is not a finite decimal number");
        // What is accepted is read as written: decimal, never octal.
        CommonOptions o;
        REQUIRE(usage({"--width", "010", "--height", "0007", "--seed", "18446744073709551615",
                       "--fov", "45.5", "--threads", "0"},
                      &o) == "(accepted)");
        CHECK(o.width == 10);
        CHECK(o.height == 7);
        CHECK(o.seed == UINT64_MAX);
        CHECK(o.fov == 45.5f);
        CHECK(o.threads == 0);
    }
    TEST_CASE("hard case: vector flags that overflow or have trailing junk are refused") {
        auto message = [](const std::string& text) {
            try {
                parseVec3(text, "--eye");
            } catch (const InputError& e) {
                return std::string(e.what());
            }
            return std::string("(accepted)");
        };
        CHECK(message("1e39,0,0") == "--eye: '1e39' is not a finite number");
        CHECK(message("0,0,-1e39") == "--eye: '-1e39' is not a finite number");
        CHECK(message("1,2,3x") == "--eye: '3x' is not a finite number");
        CHECK(message("1,2,3,4") == "--eye: '3,4' is not a finite number");
        CHECK(message("0x1p3,0,0") == "--eye: '0x1p3' is not a finite number");
        CHECK(message(" 1,2,3") == "--eye: ' 1' is not a finite number");
        CHECK(message("nan,0,0") == "--eye: 'nan' is not a finite number");
        CHECK(message("1,2") == "--eye: expected X,Y,Z, got '1,2'");
        // Fractions are what a vector holds: each component the nearest float.
        CHECK(parseVec3("0.5,-2.25,1e-3", "--eye") == Vec3(0.5f, -2.25f, 1e-3f));
    }
    TEST_CASE(
        "hard case: a rays file with trailing bytes or an infinite origin is refused by trace") {
        // Binary float32: a trailing partial record is junk, an infinity an overflow.
        auto message = [](std::vector<float> values, size_t extra) {
            std::string bytes(reinterpret_cast<const char*>(values.data()),
                              values.size() * sizeof(float));
            bytes.append(extra, '\x7f');
            try {
                parseRays(bytes.data(), bytes.size(), "rays file 'r.bin'");
            } catch (const InputError& e) {
                return std::string(e.what());
            }
            return std::string("(accepted)");
        };
        const std::vector<float> ray = {0.2f, 0.2f, 5.0f, 0.0f, 0.0f, 0.0f, -1.0f, 1e30f};
        CHECK(message(ray, 0) == "(accepted)");
        CHECK(message(ray, 1) ==
              "rays file 'r.bin': size 33 bytes is not a multiple of 32 (8 float32 per ray)");
        std::vector<float> far = ray;
        far[0] = kInfinity<float>;
        CHECK(message(far, 0) == "rays file 'r.bin': ray 0: infinite origin or direction");
    }
}

#ifdef BOXES_PROGRAM_01
TEST_SUITE("hard cases reliability") {
    TEST_CASE(
        "hard case: every numeric flag of every step program and of trace and check refuses "
        "overflow and fractions and junk") {
        // Each program's --help names every option with its type (INT, UINT, FLOAT): each of
        // them gets an overflowing, a fractional (integers) or non-finite (floats) and a
        // trailing-junk value. The common flags are also checked in-process above.
        struct Command {
            std::string name, path, prefix, help;
        };
        test::TempDir dir;
        std::ofstream(dir.file("m.obj")) << triangleThen("f 1 2 3\n");
        const float ray[8] = {0.2f, 0.2f, 5.0f, 0.0f, 0.0f, 0.0f, -1.0f, 1e30f};
        std::ofstream(dir.file("r.bin"), std::ios::binary)
            .write(reinterpret_cast<const char*>(ray), sizeof ray);
        const std::string png = "--headless --width 8 --height 6 --out bad.png ";
        const std::vector<Command> commands = {
            {"01_triangle", BOXES_PROGRAM_01, png, "--help"},
            {"02_box", BOXES_PROGRAM_02, png, "--help"},
            {"03_aabb", BOXES_PROGRAM_03, png, "--help"},
            {"04_bvh", BOXES_PROGRAM_04, png, "--help"},
            {"04_bvh", BOXES_PROGRAM_04, "trace --mesh m.obj --rays r.bin --hits bad.png ",
             "trace --help"},
            {"04_bvh", BOXES_PROGRAM_04, "check --mesh m.obj --rays r.bin ", "check --help"},
            {"05_efficiency", BOXES_PROGRAM_05, png, "--help"},
            {"06_raster", BOXES_PROGRAM_06, png, "--help"}};
        size_t checked = 0;
        for (const Command& c : commands) {
            auto help = test::runProgram(c.path, c.help, dir);
            REQUIRE(help.exitCode == 0);
            std::istringstream lines(help.out);
            for (std::string line; std::getline(lines, line);) {
                // "  --width INT:INT in [1 - 16384]" or "  -n,--count UINT ..."
                std::istringstream words(line);
                std::string names, type;
                words >> names >> type;
                size_t dashes = names.find("--");
                if (dashes == std::string::npos) continue;
                std::string flag = names.substr(dashes);
                std::string kind = type.substr(0, type.find_first_of(":="));
                std::vector<std::pair<std::string, std::string>> bad;
                if (kind == "INT" || kind == "UINT")
                    bad = {{"99999999999999999999", "is out of range"},
                           {"2.5", "is not a decimal integer"},
                           {"8abc", "is not a decimal integer"}};
                else if (kind == "FLOAT")
                    bad = {{"1e999", "is out of range"},
                           {"nan", "is not a finite decimal number"},
                           {"2.5abc", "is not a finite decimal number"}};
                for (const auto& [value, why] : bad) {
                    INFO(c.name << " " << c.prefix << flag << " " << value);
                    auto run = test::runProgram(c.path, c.prefix + flag + " " + value, dir);
                    CHECK(run.exitCode == 2);
                    CHECK(run.err == c.name + ": error: " + flag + ": '" + value + "' " + why +
                                         " (see --help)\n");
                    CHECK_FALSE(std::filesystem::exists(dir.file("bad.png")));
                    ++checked;
                }
            }
        }
        // Every program's --width --height --seed --threads --fov --frames, and more.
        CHECK(checked >= 3 * (6 * 6 + 4));
    }
}
#endif
