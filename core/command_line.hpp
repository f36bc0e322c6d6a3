// The frame of every program's command line: its flags parsed with strict numbers, help,
// and every error turned into one line and an exit code. The common flags are core/app.hpp's.
#pragma once

#include <functional>
#include <string>

// CLI11 declared, not included: <CLI/CLI.hpp> costs a file about 9 s of compile time (its
// parser and the code of its global validators), and most files that include this header
// never build a command line. Those that do include it themselves.
namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace boxes {

// Parses; a help request prints help and exits 0; a bad flag throws UsageError.
void parseCommandLine(CLI::App& app, int argc, char** argv);

struct ExitRequest {
    int code = 0;
};

// Runs body and turns every error into one line on stderr and an exit code:
// 0 success, 1 bad input or failure, 2 bad command line, 3 an exercise not implemented.
int runMain(const std::string& program, const std::function<int()>& body);

}  // namespace boxes
