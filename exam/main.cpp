// Exam practice for self-study: seeded questions, typed answers checked with a stated
// tolerance, and a worked solution after each question; or a timed mock exam in the form of
// the lecture's example exam, scored per part at the end, and its printable sheet.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "core/command_line.hpp"
#include "core/mesh.hpp"  // InputError, UsageError
#include "exam/answer.hpp"
#include "exam/mock.hpp"
#include "exam/questions.hpp"
#include "exam/run_mock.hpp"
#include "exam/sheet.hpp"
#include "exam/terminal.hpp"

using namespace boxes;
using namespace boxes::exam;

namespace {

// Reads answer lines; blank lines and lines starting with # are skipped in a file.
struct AnswerSource {
    std::istream* in;
    bool interactive;
    bool next(std::string& line) {
        while (std::getline(*in, line)) {
            if (!line.empty() && line.back() == '\r') line.pop_back();
            if (!interactive && (normalizeWords(line).empty() || line.starts_with("#"))) continue;
            return true;
        }
        return false;
    }
};

void printQuestion(std::ostream& out, const Question& q, int number, int total, int width) {
    out << "\n"
        << wrapText("== Question " + std::to_string(number) + " of " + std::to_string(total) +
                        ": " + q.kind + " (repeat it with --kind " + q.kind + " --seed " +
                        std::to_string(q.seed) + ")",
                    width, 3)
        << "\n"
        << wrapText(q.statement, width, 2) << "\n";
}

void printSolution(std::ostream& out, const Question& q, int width) {
    out << "  Worked solution:\n";
    for (const std::string& step : q.solution) out << wrapText("    " + step, width, 2) << "\n";
    for (const Part& p : q.parts)
        out << wrapText("  Answer: " + p.prompt + ": " + p.shown, width, 4) << "\n";
}

// The step 05 report the kind cost-order asks about: --report, else the tour's.
MeasuredCosts measuredCosts(const std::string& reportPath) {
    if (!reportPath.empty()) {
        try {
            return readMeasuredCosts(reportPath);
        } catch (const std::runtime_error& e) {
            throw InputError(std::string("--report: ") + e.what());
        }
    }
    const std::string tour = "out/05_efficiency.json";
    if (std::filesystem::exists(tour)) {
        try {
            return readMeasuredCosts(tour);
        } catch (const std::runtime_error&) {
            // A report from an older or interrupted run: the reference figures instead.
        }
    }
    MeasuredCosts reference = referenceCosts();
    reference.source +=
        " (yours is not there yet: `./workbook tour`, or `./workbook run 05 "
        "--headless --measure --report out/05_efficiency.json`, measures it)";
    return reference;
}

}  // namespace

int main(int argc, char** argv) {
    return runMain("exam_practice", [&] {
        CLI::App app{
            "Exam practice: questions with seeded random numbers, your answers checked, "
            "and a worked solution; or --mock, a timed mock exam in the form of the lecture's "
            "example exam, scored per part at the end. Answers: numbers or vectors such as "
            "(1, 2, 3), 1 2 3 or sqrt(10)-1; 'none' when there is no hit; yes/no; letters."};
        std::vector<std::string> kinds;
        uint64_t seed = 0;
        int count = 5;
        int width = -1;
        double minutes = 90.0;
        std::string answersPath, sheetDir, reportPath;
        bool list = false, show = false, mock = false, noPdf = false;
        app.add_option("--kind", kinds,
                       "question kinds to ask (default: a random mix; see --list)");
        app.add_option("--seed", seed,
                       "seed of the first question, or of the mock exam (default: from the "
                       "clock); question i uses seed + i");
        app.add_option("--count", count, "how many questions")->check(CLI::Range(1, 1000));
        app.add_option("--answers", answersPath,
                       "non-interactive: read the answers from this file ('-' for stdin), one "
                       "line per answer; blank lines and # comments are skipped");
        app.add_flag("--list", list, "list the question kinds and exit");
        app.add_flag("--show", show,
                     "print the questions with their worked solutions, ask nothing");
        app.add_flag("--mock", mock,
                     "a mock exam: a full sheet in the form of the lecture's example exam, "
                     "timed, scored per part at the end, then the worked solutions");
        app.add_option("--minutes", minutes, "the mock exam's time limit (default 90)")
            ->check(CLI::Range(0.001, 1000.0));
        app.add_option("--sheet", sheetDir,
                       "write the mock exam as a printable sheet, its answer key and an answer "
                       "file into this folder (HTML; PDF where Chromium is installed), ask "
                       "nothing");
        app.add_flag("--no-pdf", noPdf, "with --sheet: the HTML pages only, no PDF");
        app.add_option("--report", reportPath,
                       "step 05's report for the cost questions (default: "
                       "out/05_efficiency.json when the tour wrote it, else a reference run)");
        app.add_option("--width", width,
                       "wrap the text at this many columns, 0 never (default: the terminal's)")
            ->check(CLI::Range(0, 10000));
        parseCommandLine(app, argc, argv);
        if (width < 0) width = terminalWidth();

        if (list) {
            // The name, then its description wrapped beside it.
            for (const QuestionKind& k : questionKinds()) {
                size_t column = std::max<size_t>(16, k.name.size() + 1);
                std::string text =
                    wrapText(k.description, width > 0 ? std::max(20, width - int(column)) : 0, 0);
                std::string indented = k.name + std::string(column - k.name.size(), ' ');
                for (char c : text)
                    indented += c == '\n' ? "\n" + std::string(column, ' ') : std::string(1, c);
                std::cout << indented << "\n";
            }
            return 0;
        }
        bool seeded = app.count("--seed") > 0;
        if (!seeded)
            seed = uint64_t(std::chrono::system_clock::now().time_since_epoch().count()) % 100000;
        MeasuredCosts costs = measuredCosts(reportPath);
        if (!sheetDir.empty() || mock) {
            if (!kinds.empty()) throw UsageError("--kind: the mock exam draws its own kinds");
            // A sheet for printing is the same on every machine: the reference run's costs,
            // unless --report names a run.
            bool printing = !sheetDir.empty();
            MockSheet sheet =
                makeMockSheet(seed, printing && reportPath.empty() ? referenceCosts() : costs);
            if (printing) {
                WrittenSheet w = writeSheet(sheet, minutes, sheetDir, !noPdf);
                for (const std::string& f : w.files) std::cout << "wrote " << f << "\n";
                if (!w.note.empty()) std::cout << w.note << "\n";
                return 0;
            }
            MockRun run;
            run.minutes = minutes;
            run.answersPath = answersPath;
            run.width = width;
            run.show = show;
            return runMock(sheet, run, std::cout);
        }
        for (const std::string& k : kinds) makeQuestion(k, 0, costs);  // unknown kinds fail here

        std::unique_ptr<std::ifstream> file;
        AnswerSource answers{&std::cin, answersPath.empty()};
        if (!answersPath.empty() && answersPath != "-") {
            file = std::make_unique<std::ifstream>(answersPath);
            if (!*file) throw InputError("--answers: cannot read '" + answersPath + "'");
            answers.in = file.get();
        }

        std::ostream& out = std::cout;
        if (!show)
            out << wrapText(std::string("Exam practice: ") + toleranceText() +
                                ". Type 'none' when there is no hit, and an empty line or "
                                "Ctrl-D to stop.",
                            width, 0)
                << "\n";
        int asked = 0, correct = 0, partsTotal = 0;
        bool stopped = false;
        for (int i = 0; i < count && !stopped; ++i) {
            uint64_t s = seed + uint64_t(i);
            const std::vector<QuestionKind>& all = questionKinds();
            // Without --kind: a mix that walks through the kinds from a seeded start.
            std::string kind = kinds.empty() ? all[size_t((s * 7) % all.size())].name
                                             : kinds[size_t(i) % kinds.size()];
            Question q = makeQuestion(kind, s, costs);
            printQuestion(out, q, i + 1, count, width);
            if (show) {
                printSolution(out, q, width);
                continue;
            }
            for (const Part& p : q.parts) {
                out << wrapText("  " + p.prompt + "?", width, 4) << " " << std::flush;
                Checked c{Verdict::Unreadable, ""};
                std::string line;
                for (;;) {
                    if (!answers.next(line) ||
                        (answers.interactive && normalizeWords(line).empty())) {
                        stopped = true;
                        break;
                    }
                    if (!answers.interactive) out << line << "\n";
                    c = checkAnswer(p, line);
                    if (c.verdict != Verdict::Unreadable || !answers.interactive) break;
                    out << wrapText("  (" + c.note + "; try again) " + p.prompt + "?", width, 4)
                        << " " << std::flush;
                }
                if (stopped) break;
                ++partsTotal;
                if (c.verdict == Verdict::Correct) {
                    ++correct;
                    out << "  correct\n";
                } else {
                    out << wrapText("  wrong" + (c.note.empty() ? "" : " (" + c.note + ")") +
                                        "; the answer is " + p.shown,
                                    width, 4)
                        << "\n";
                }
            }
            if (stopped && partsTotal == 0 && asked == 0) break;
            ++asked;
            printSolution(out, q, width);
        }
        if (!show) out << "\nScore: " << correct << " of " << partsTotal << " answers correct\n";
        return 0;
    });
}
