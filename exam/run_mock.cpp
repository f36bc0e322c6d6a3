#include "exam/run_mock.hpp"

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <memory>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include "exam/answer.hpp"
#include "exam/terminal.hpp"

namespace boxes::exam {

namespace {

std::string points(double p) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(std::abs(p - std::round(p)) < 1e-9 ? 0 : 1) << p;
    return s.str();
}

std::string partStatement(const MockPart& p) {
    std::string statement = p.question.statement;
    std::string prefix = std::string(1, p.letter) + ". ";
    if (statement.starts_with(prefix)) statement = statement.substr(prefix.size());
    return statement;
}

// Where the answers come from: a file (comments and blank lines skipped), a pipe or a
// terminal (read against the clock).
class Answers {
public:
    explicit Answers(const std::string& path) {
        if (!path.empty() && path != "-") {
            file_ = std::make_unique<std::ifstream>(path);
            if (!*file_) throw std::runtime_error("--answers: cannot read '" + path + "'");
        }
        interactive_ = path.empty();
    }
    bool interactive() const { return interactive_; }
    // The next answer; nothing at the end of the input or when the time is up.
    std::optional<std::string> next(const ExamClock& clock) {
        for (;;) {
            std::optional<std::string> line;
            if (file_) {
                std::string l;
                if (!std::getline(*file_, l)) return std::nullopt;
                if (!l.empty() && l.back() == '\r') l.pop_back();
                line = l;
            } else {
                line = readLineUntil(STDIN_FILENO, clock);
                if (!line) return std::nullopt;
            }
            if (!interactive_ && (line->starts_with("#") || normalizeWords(*line).empty()))
                continue;
            return line;
        }
    }

private:
    std::unique_ptr<std::ifstream> file_;
    bool interactive_ = false;
};

void printSheetHead(const MockSheet& sheet, const MockRun& run, std::ostream& out) {
    std::string head =
        "Mock exam, seed " + std::to_string(sheet.seed) + ": " +
        std::to_string(sheet.questions.size()) + " questions, " + points(sheet.points()) +
        " points, " + limitText(run.minutes) +
        ". In the form of the lecture's example exam: question 1 is its first "
        "question, question 2 its second with more of the lecture's terms; 3 and 4 ask the rest "
        "of what the lecture expects. The lecture gives no points per part; these are the "
        "workbook's.\n"
        "Answers: " +
        std::string(toleranceText()) +
        "; 'none' when a ray hits nothing; yes or no; letters. 'skip' (or an empty line) leaves "
        "an answer out, Ctrl-D ends the exam. Nothing is marked before the end.";
    out << wrapText(head, run.width, 0) << "\n";
}

void printPart(const MockPart& p, std::ostream& out, int width) {
    out << wrapText(
               std::string(1, p.letter) + ". (" + points(p.points) + " points) " + partStatement(p),
               width, 3)
        << "\n";
}

void printScore(const MockSheet& sheet, const Score& s, double seconds, bool timeUp,
                std::ostream& out, int width) {
    out << "\n== Score" << (timeUp ? " (the time was up)" : "") << "\n";
    int question = 0;
    for (const Score::PartScore& p : s.parts) {
        if (p.question != question) {
            question = p.question;
            const MockQuestion& q = sheet.questions[size_t(question - 1)];
            out << wrapText("Question " + std::to_string(q.number) + ": " + q.title, width, 2)
                << "\n";
        }
        std::string score = points(p.earned) + " / " + points(p.points);
        std::string row = "  " + std::string(1, p.letter) + "  " +
                          std::string(score.size() < 9 ? 9 - score.size() : 0, ' ') + score +
                          "   " + p.topic;
        if (p.lines > 1)
            row += " (" + std::to_string(p.right) + " of " + std::to_string(p.lines) + " right)";
        out << wrapText(row, width, 8) << "\n";
    }
    double percent = s.total > 0 ? 100.0 * s.earned / s.total : 0.0;
    out << "Total: " << points(s.earned) << " of " << points(s.total) << " points ("
        << int(std::round(percent)) << "%), in " << clockText(seconds) << "\n";
}

void printSolutions(const MockSheet& sheet, const Score* s, std::ostream& out, int width) {
    out << "\n== Worked solutions\n";
    size_t i = 0;
    for (const MockQuestion& q : sheet.questions) {
        out << "\n"
            << wrapText("Question " + std::to_string(q.number) + ": " + q.title, width, 2) << "\n";
        if (!q.statement.empty()) out << wrapText(q.statement, width, 2) << "\n";
        for (const MockPart& p : q.parts) {
            printPart(p, out, width);
            for (const Part& line : p.question.parts) {
                std::string text = "   " + line.prompt + ": " + line.shown;
                if (s) {
                    const LineResult& r = s->lines[i];
                    text += !r.answered ? "  (not answered)"
                            : r.earned > 0
                                ? "  (yours: " + r.answer + ", right)"
                                : "  (yours: " + r.answer + ", wrong" +
                                      (r.checked.note.empty() ? "" : ": " + r.checked.note) + ")";
                }
                out << wrapText(text, width, 5) << "\n";
                ++i;
            }
            for (const std::string& step : p.question.solution)
                out << wrapText("     " + step, width, 2) << "\n";
            if (p.question.kind != "example-1" && p.question.kind != "terminology")
                out << wrapText("     (more of this kind: --kind " + p.question.kind + " --seed " +
                                    std::to_string(p.question.seed) + ")",
                                width, 2)
                    << "\n";
        }
    }
    if (!sheet.costsSource.empty())
        out << wrapText("\nQuestion 4e's figures: " + sheet.costsSource + ".", width, 2) << "\n";
}

}  // namespace

int runMock(const MockSheet& sheet, const MockRun& run, std::ostream& out) {
    if (run.show) {
        printSheetHead(sheet, run, out);
        printSolutions(sheet, nullptr, out, run.width);
        return 0;
    }
    Answers answers(run.answersPath);
    bool live = answers.interactive() && isatty(STDOUT_FILENO) && isatty(STDIN_FILENO);
    if (const char* term = std::getenv("TERM"); !term || std::string(term) == "dumb") live = false;
    printSheetHead(sheet, run, out);
    out << std::flush;
    ExamClock clock(run.minutes * 60.0, live);
    std::vector<std::string> given;
    bool ended = false;
    std::vector<AnswerSlot> slots = answerSlots(sheet);
    size_t slot = 0;
    for (const MockQuestion& q : sheet.questions) {
        if (ended) break;
        out << "\n"
            << wrapText("== Question " + std::to_string(q.number) + " (" + points(q.points()) +
                            " points): " + q.title,
                        run.width, 3)
            << "\n";
        if (!q.statement.empty()) out << wrapText(q.statement, run.width, 2) << "\n";
        for (const MockPart& p : q.parts) {
            if (ended) break;
            printPart(p, out, run.width);
            for (const Part& line : p.question.parts) {
                for (;;) {
                    // The clock's time left when asked; the space after the question mark
                    // survives the wrapping.
                    std::string prompt = "   " + slots[slot].label + " " + line.prompt + "?";
                    if (answers.interactive())
                        prompt = "   [" + clockText(clock.left()) + " left] " + prompt.substr(3);
                    out << wrapText(prompt, run.width, 5) << " " << std::flush;
                    std::optional<std::string> a = answers.next(clock);
                    if (!a) {
                        ended = true;
                        break;
                    }
                    if (!answers.interactive()) out << *a << "\n";
                    Checked c = isSkip(*a) ? Checked{Verdict::Wrong, ""} : checkAnswer(line, *a);
                    if (answers.interactive() && c.verdict == Verdict::Unreadable) {
                        out << "     (" << c.note << "; try again)\n";
                        continue;
                    }
                    given.push_back(*a);
                    break;
                }
                if (ended) break;
                ++slot;
            }
        }
    }
    double seconds = clock.elapsed();
    bool timeUp = clock.up();
    clock.stop();
    if (ended)
        out << "\n"
            << (timeUp ? "The time is up." : "The answers ended.")
            << " What is not answered counts 0.\n";
    Score s = scoreSheet(sheet, given);
    printScore(sheet, s, seconds, timeUp, out, run.width);
    printSolutions(sheet, &s, out, run.width);
    return 0;
}

}  // namespace boxes::exam
