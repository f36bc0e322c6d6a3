#include "exam/sheet.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "exam/answer.hpp"
#include "exam/terminal.hpp"

extern char** environ;

namespace boxes::exam {

namespace fs = std::filesystem;

namespace {

std::string escape(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

std::string pointsText(double p) {
    std::ostringstream s;
    s << (std::abs(p - std::round(p)) < 1e-9 ? std::round(p) : std::round(p * 10) / 10);
    return s.str() + (p == 1.0 ? " point" : " points");
}

// A statement's lines: code (four spaces) in a block, choices ("  a) ...") as lines, the
// rest as paragraphs.
std::string statementHtml(const std::string& text) {
    std::string out, code;
    std::istringstream lines(text);
    std::string line;
    auto flush = [&] {
        if (code.empty()) return;
        out += "<pre>" + escape(code) + "</pre>\n";
        code.clear();
    };
    while (std::getline(lines, line)) {
        if (line.starts_with("    ")) {
            code += line.substr(4) + "\n";
            continue;
        }
        flush();
        if (line.starts_with("  "))
            out += "<p class=\"choice\">" + escape(line.substr(2)) + "</p>\n";
        else if (!line.empty())
            out += "<p>" + escape(line) + "</p>\n";
    }
    flush();
    return out;
}

const char* kStyle = R"(
@page { size: A4; margin: 16mm 16mm 18mm 16mm; }
* { box-sizing: border-box; }
body { font-family: "DejaVu Sans", "Liberation Sans", Arial, sans-serif; font-size: 10pt;
       line-height: 1.35; color: #111; max-width: 178mm; margin: 0 auto; }
h1 { font-size: 16pt; margin: 0 0 2mm 0; }
h2 { font-size: 12pt; margin: 6mm 0 2mm 0; border-bottom: 1px solid #888; padding-bottom: 1mm; }
.meta { color: #333; margin: 0 0 2mm 0; }
.rules { border: 1px solid #bbb; padding: 2mm 3mm; margin: 2mm 0 4mm 0; font-size: 9pt; }
.rules p { margin: 1mm 0; }
.givens { margin: 1mm 0 2mm 0; }
.part { break-inside: avoid; margin: 3mm 0 4mm 0; }
.part > .head { font-weight: bold; }
.part .pts { font-weight: normal; color: #444; float: right; }
p { margin: 1mm 0; overflow-wrap: break-word; }
p.choice { margin-left: 6mm; }
pre { font-family: "DejaVu Sans Mono", "Liberation Mono", monospace; font-size: 8.5pt;
      background: #f4f4f4; border: 1px solid #ddd; padding: 2mm; margin: 1.5mm 0;
      white-space: pre-wrap; }
.line { display: flex; gap: 3mm; align-items: flex-end; margin: 2mm 0 0 4mm; }
.line .prompt { flex: 0 1 auto; max-width: 60%; font-size: 9pt; color: #222; }
.line .box { flex: 1 1 auto; min-height: 9mm; border-bottom: 1px solid #555; }
.line .answer { flex: 1 1 auto; font-family: "DejaVu Sans Mono", monospace; font-size: 9pt;
                border-bottom: 1px solid #bbb; padding: 0 1mm; overflow-wrap: anywhere; }
.work { min-height: 18mm; }
.solution { margin: 2mm 0 0 4mm; font-size: 9pt; color: #222; }
.solution ol { margin: 1mm 0 0 0; padding-left: 6mm; }
.solution li { overflow-wrap: anywhere; }
.practice { font-size: 8pt; color: #555; }
code { white-space: nowrap; }
)";

}  // namespace

std::string sheetHtml(const MockSheet& sheet, double minutes, bool key) {
    std::string seed = std::to_string(sheet.seed);
    std::ostringstream h;
    h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>Mock exam, "
         "seed "
      << seed << (key ? ": answer key" : "") << "</title>\n<style>" << kStyle
      << "</style>\n</head>\n<body>\n";
    h << "<h1>Boxes workbook: mock exam" << (key ? " &mdash; answer key" : "") << "</h1>\n";
    h << "<p class=\"meta\">Seed " << seed << " &middot; " << sheet.questions.size()
      << " questions &middot; " << pointsText(sheet.points()) << " &middot; "
      << escape(limitText(minutes)) << "</p>\n";
    h << "<div class=\"rules\">"
      << "<p>In the form of the lecture's example exam: question 1 is its first question, "
         "question 2 its second with more of the lecture's terms; questions 3 and 4 ask the "
         "rest of what the lecture expects (light transport; vectors, boxes, efficiency). The "
         "lecture gives no points per part: the points here are the workbook's.</p>"
      << "<p>Give numbers to three decimals or exactly, as sqrt(10) - 1: "
      << escape(toleranceText()) << ". Write <i>none</i> where a ray hits nothing.</p>"
      << "<p>To have it marked: type the answers into the answer file, one a line, and run "
         "<code>./workbook exam --mock --seed "
      << seed << " --answers FILE</code>.</p></div>\n";
    for (const MockQuestion& q : sheet.questions) {
        h << "<h2>Question " << q.number << " &middot; " << escape(q.title) << " ("
          << pointsText(q.points()) << ")</h2>\n";
        if (!q.statement.empty())
            h << "<div class=\"givens\">" << statementHtml(q.statement) << "</div>\n";
        for (const MockPart& p : q.parts) {
            std::string statement = p.question.statement;
            std::string prefix = std::string(1, p.letter) + ". ";
            if (statement.starts_with(prefix)) statement = statement.substr(prefix.size());
            h << "<div class=\"part\">\n<p class=\"head\">" << p.letter << ". " << escape(p.topic)
              << "<span class=\"pts\">" << pointsText(p.points) << "</span></p>\n"
              << statementHtml(statement);
            for (const Part& line : p.question.parts) {
                h << "<div class=\"line\"><span class=\"prompt\">" << escape(line.prompt)
                  << "</span>";
                if (key)
                    h << "<span class=\"answer\">" << escape(line.shown) << "</span>";
                else
                    h << "<span class=\"box\"></span>";
                h << "</div>\n";
            }
            if (key) {
                h << "<div class=\"solution\">Worked solution:<ol>";
                for (const std::string& s : p.question.solution)
                    h << "<li>" << escape(s) << "</li>";
                h << "</ol>";
                if (p.question.kind != "example-1" && p.question.kind != "terminology")
                    h << "<p class=\"practice\">More of this kind: <code>./workbook exam --kind "
                      << escape(p.question.kind) << " --seed " << p.question.seed << "</code></p>";
                h << "</div>\n";
            } else {
                h << "<div class=\"work\"></div>\n";
            }
            h << "</div>\n";
        }
    }
    if (sheet.costsSource.size())
        h << "<p class=\"practice\">Question 4e's figures: " << escape(sheet.costsSource)
          << ".</p>\n";
    h << "</body>\n</html>\n";
    return h.str();
}

namespace {

std::string chromium() {
    if (const char* env = std::getenv("CHROME_PATH"); env && *env && access(env, X_OK) == 0)
        return env;
    for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
        if (access(p, X_OK) == 0) return p;
    return "";
}

// Chromium prints the page to PDF; a fresh profile in DIR, removed afterwards. True when
// the PDF is there.
bool printPdf(const std::string& browser, const fs::path& html, const fs::path& pdf,
              const fs::path& dir) {
    fs::path profile = dir / (".chromium-profile-" + std::to_string(getpid()));
    fs::create_directories(profile);
    std::vector<std::string> args = {browser,
                                     "--headless",
                                     "--no-sandbox",
                                     "--disable-gpu",
                                     "--disable-background-networking",
                                     "--no-first-run",
                                     "--user-data-dir=" + profile.string(),
                                     "--no-pdf-header-footer",
                                     "--print-to-pdf=" + pdf.string(),
                                     "file://" + fs::absolute(html).string()};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
    pid_t pid;
    int rc = posix_spawn(&pid, browser.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    int status = 0;
    if (rc == 0) waitpid(pid, &status, 0);
    std::error_code ignored;
    fs::remove_all(profile, ignored);
    return rc == 0 && fs::exists(pdf) && fs::file_size(pdf) > 1000;
}

void writeFile(const fs::path& path, const std::string& text) {
    std::ofstream out(path);
    out << text;
    if (!out) throw std::runtime_error("cannot write '" + path.string() + "'");
}

}  // namespace

WrittenSheet writeSheet(const MockSheet& sheet, double minutes, const std::string& dir, bool pdf) {
    fs::path d(dir);
    std::error_code error;
    fs::create_directories(d, error);
    if (!fs::is_directory(d)) throw std::runtime_error("cannot create the folder '" + dir + "'");
    std::string base = "mock-" + std::to_string(sheet.seed);
    WrittenSheet w;
    fs::path html = d / (base + ".html"), keyHtml = d / (base + "-key.html"),
             answers = d / (base + "-answers.txt"), keyAnswers = d / (base + "-key.txt");
    writeFile(html, sheetHtml(sheet, minutes, false));
    writeFile(keyHtml, sheetHtml(sheet, minutes, true));
    writeFile(answers, answerTemplate(sheet, false));
    writeFile(keyAnswers, answerTemplate(sheet, true));
    w.files = {html.string(), keyHtml.string(), answers.string(), keyAnswers.string()};
    if (!pdf) return w;
    std::string browser = chromium();
    if (browser.empty()) {
        w.note =
            "no PDF: Chromium is not installed (the Debian package chromium; or set "
            "CHROME_PATH); print the HTML pages from a browser";
        return w;
    }
    for (const fs::path& page : {html, keyHtml}) {
        fs::path pdf = page;
        pdf.replace_extension(".pdf");
        if (printPdf(browser, page, pdf, d))
            w.files.push_back(pdf.string());
        else
            w.note =
                "Chromium did not print " + pdf.string() + "; print the HTML page from a browser";
    }
    return w;
}

}  // namespace boxes::exam
