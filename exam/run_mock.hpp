// The mock exam in a terminal: the sheet question by question against the clock, the
// answers typed or read from a file, the score per part at the end, then the worked
// solutions.
#pragma once

#include <iosfwd>
#include <string>

#include "exam/mock.hpp"

namespace boxes::exam {

struct MockRun {
    double minutes = 90.0;    // the time limit
    std::string answersPath;  // empty: typed; "-": stdin (a pipe); else a file
    int width = 80;           // wrap at this many columns (0: never)
    bool show = false;        // print the sheet with its key, ask nothing
};

// Runs the mock exam on `out`; returns the exit code (0). Throws std::runtime_error when the
// answer file cannot be read.
int runMock(const MockSheet& sheet, const MockRun& run, std::ostream& out);

}  // namespace boxes::exam
