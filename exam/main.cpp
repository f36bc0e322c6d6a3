// Exam practice for self-study: seeded questions, typed answers checked with a stated
// tolerance, and a worked solution after each question.
#include <fstream>
#include <iostream>
#include <memory>

#include "core/app.hpp"
#include "exam/answer.hpp"
#include "exam/questions.hpp"

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

void printQuestion(std::ostream& out, const Question& q, int number, int total) {
    out << "\n== Question " << number << " of " << total << ": " << q.kind
        << " (repeat it with --kind " << q.kind << " --seed " << q.seed << ")\n"
        << q.statement << "\n";
}

void printSolution(std::ostream& out, const Question& q) {
    out << "  Worked solution:\n";
    for (const std::string& step : q.solution) out << "    " << step << "\n";
    for (const Part& p : q.parts) out << "  Answer: " << p.prompt << ": " << p.shown << "\n";
}

}  // namespace

int main(int argc, char** argv) {
    return runMain("exam_practice", [&] {
        CLI::App app{
            "Exam practice: questions with seeded random numbers, your answers checked, "
            "and a worked solution. Answers: numbers or vectors such as (1, 2, 3), "
            "1 2 3 or sqrt(10)-1; 'none' when there is no hit; yes/no; a letter."};
        std::vector<std::string> kinds;
        uint64_t seed = 0;
        int count = 5;
        std::string answersPath;
        bool list = false, show = false;
        app.add_option("--kind", kinds,
                       "question kinds to ask (default: a random mix; see --list)");
        app.add_option("--seed", seed,
                       "seed of the first question (default: from the clock); "
                       "question i uses seed + i");
        app.add_option("--count", count, "how many questions")->check(CLI::Range(1, 1000));
        app.add_option("--answers", answersPath,
                       "non-interactive: read the answers from this file ('-' for stdin), one "
                       "line per part; blank lines and # comments are skipped");
        app.add_flag("--list", list, "list the question kinds and exit");
        app.add_flag("--show", show,
                     "print the questions with their worked solutions, ask nothing");
        parseCommandLine(app, argc, argv);

        if (list) {
            for (const QuestionKind& k : questionKinds())
                std::cout << k.name << std::string(k.name.size() < 16 ? 16 - k.name.size() : 1, ' ')
                          << k.description << "\n";
            return 0;
        }
        bool seeded = app.count("--seed") > 0;
        if (!seeded)
            seed = uint64_t(std::chrono::system_clock::now().time_since_epoch().count()) % 100000;
        for (const std::string& k : kinds) makeQuestion(k, 0);  // unknown kinds fail here

        std::unique_ptr<std::ifstream> file;
        AnswerSource answers{&std::cin, answersPath.empty()};
        if (!answersPath.empty() && answersPath != "-") {
            file = std::make_unique<std::ifstream>(answersPath);
            if (!*file) throw InputError("--answers: cannot read '" + answersPath + "'");
            answers.in = file.get();
        }

        std::ostream& out = std::cout;
        if (!show)
            out << "Exam practice: " << toleranceText() << ". Type 'none' when there is no hit, "
                << "and an empty line or Ctrl-D to stop.\n";
        int asked = 0, correct = 0, partsTotal = 0;
        bool stopped = false;
        for (int i = 0; i < count && !stopped; ++i) {
            uint64_t s = seed + uint64_t(i);
            const std::vector<QuestionKind>& all = questionKinds();
            // Without --kind: a mix that walks through the kinds from a seeded start.
            std::string kind = kinds.empty() ? all[size_t((s * 7) % all.size())].name
                                             : kinds[size_t(i) % kinds.size()];
            Question q = makeQuestion(kind, s);
            printQuestion(out, q, i + 1, count);
            if (show) {
                printSolution(out, q);
                continue;
            }
            for (const Part& p : q.parts) {
                out << "  " << p.prompt << "? " << std::flush;
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
                    out << "  (" << c.note << "; try again) " << p.prompt << "? " << std::flush;
                }
                if (stopped) break;
                ++partsTotal;
                if (c.verdict == Verdict::Correct) {
                    ++correct;
                    out << "  correct\n";
                } else {
                    out << "  wrong" << (c.note.empty() ? "" : " (" + c.note + ")")
                        << "; the answer is " << p.shown << "\n";
                }
            }
            if (stopped && partsTotal == 0 && asked == 0) break;
            ++asked;
            printSolution(out, q);
        }
        if (!show) out << "\nScore: " << correct << " of " << partsTotal << " answers correct\n";
        return 0;
    });
}
