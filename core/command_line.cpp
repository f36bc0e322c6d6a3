// The command line's frame, apart from the rest of the core so that a program with its own
// flags (the exam) links it alone: strict numbers, --help, one-line errors and exit codes.
#include "core/command_line.hpp"

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <iostream>

#include "core/exercise.hpp"
#include "core/mesh.hpp"

namespace boxes {

namespace {

// CLI11 reads numbers with strtoll, strtoull and strtold in base 0: "-1" for an unsigned
// flag wrapped to 2^64 - 1, an unsigned overflow became 2^64 - 1, "010" was octal 8 and
// "0x10" 16, and "1e999" or "nan" reached the range checks. Every numeric flag's text is
// checked first: a decimal integer ("-" only for signed ones) or a finite decimal number,
// all of it; CLI11 then refuses what does not fit the flag's own type or range.
// An integer's leading zeros are dropped (CLI11 would read "010" as octal 8).
std::string strictNumber(std::string& text, const std::string& kind) {
    const char* begin = text.data();
    const char* end = begin + text.size();
    const std::string shown = "'" + printable(text, 40) + "'";
    if (kind == "FLOAT") {
        double value = 0.0;
        auto [ptr, ec] = std::from_chars(begin, end, value);
        if (ec == std::errc::result_out_of_range && ptr == end) return shown + " is out of range";
        if (ec != std::errc() || ptr != end || !std::isfinite(value))
            return shown + " is not a finite decimal number";
        return "";
    }
    uint64_t unsignedValue = 0;
    int64_t signedValue = 0;
    auto [ptr, ec] = kind == "UINT" ? std::from_chars(begin, end, unsignedValue)
                                    : std::from_chars(begin, end, signedValue);
    bool digits =
        !text.empty() && text.find_first_not_of("0123456789", text[0] == '-') == std::string::npos;
    if (ec == std::errc::result_out_of_range && ptr == end) return shown + " is out of range";
    if (ec != std::errc() || ptr != end || !digits)
        return shown + (kind == "UINT" && text[0] == '-' && digits
                            ? " is negative (a count or seed is 0 or more)"
                            : " is not a decimal integer");
    size_t sign = text[0] == '-', first = text.find_first_not_of('0', sign);
    text = text.substr(0, sign) + (first == std::string::npos ? "0" : text.substr(first));
    return "";
}

// The option's value type as CLI11 names it in the help ("INT", "UINT", "FLOAT"), before
// any validator's description.
std::string numberKind(const CLI::Option& option) {
    std::string type = option.get_type_name();
    type = type.substr(0, type.find(':'));
    return type == "INT" || type == "UINT" || type == "FLOAT" ? type : "";
}

void addStrictNumbers(CLI::App& app) {
    for (CLI::Option* option : app.get_options()) {
        std::string kind = numberKind(*option);
        // transform() puts the check before the option's own (range) checks.
        if (!kind.empty())
            option->transform(CLI::Validator(
                [kind](std::string& text) { return strictNumber(text, kind); }, "", "number"));
    }
    for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
        addStrictNumbers(*sub);
}

}  // namespace

void parseCommandLine(CLI::App& app, int argc, char** argv) {
    addStrictNumbers(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        std::cout << app.help();
        throw ExitRequest{0};
    } catch (const CLI::CallForAllHelp&) {
        std::cout << app.help("", CLI::AppFormatMode::All);
        throw ExitRequest{0};
    } catch (const CLI::ParseError& e) {
        std::string what = e.what();
        throw UsageError(what.substr(0, what.find('\n')));
    }
}

int runMain(const std::string& program, const std::function<int()>& body) {
    auto fail = [&](const std::string& message, int code) {
        std::string line = message.substr(0, message.find('\n'));
        std::cerr << program << ": " << line << "\n";
        return code;
    };
    try {
        return body();
    } catch (const ExitRequest& e) {
        return e.code;
    } catch (const UsageError& e) {
        return fail(std::string("error: ") + e.what() + " (see --help)", 2);
    } catch (const NotImplemented& e) {
        return fail(std::string(e.what()) + ": see the step's README, then run the tests", 3);
    } catch (const std::bad_alloc&) {
        return fail("error: out of memory", 1);
    } catch (const std::exception& e) {
        return fail(std::string("error: ") + e.what(), 1);
    }
}

}  // namespace boxes
