// The mock exam on paper: the sheet and its answer key as HTML pages (A4, no script, no
// network), printed to PDF by a headless Chromium where one is installed.
#pragma once

#include <string>
#include <vector>

#include "exam/mock.hpp"

namespace boxes::exam {

// The sheet (answer boxes) or the key (answers and worked solutions) as one HTML page.
std::string sheetHtml(const MockSheet& sheet, double minutes, bool key);

struct WrittenSheet {
    std::vector<std::string> files;  // every file written
    std::string note;                // why there is no PDF, when there is none
};

// DIR/mock-SEED.html, DIR/mock-SEED-key.html, DIR/mock-SEED-answers.txt (the file to fill
// in), DIR/mock-SEED-key.txt (the same filled in with the key's answers) and, where Chromium
// is ($CHROME_PATH, /usr/bin/chromium), both pages as PDF.
// Throws std::runtime_error when DIR cannot be written.
WrittenSheet writeSheet(const MockSheet& sheet, double minutes, const std::string& dir,
                        bool pdf = true);

}  // namespace boxes::exam
