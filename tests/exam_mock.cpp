// The mock exam: the sheet's form and points for many seeds, its key scoring full marks, and
// the program marking a sheet answered rightly, wrongly and by half, against the clock.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "exam/answer.hpp"
#include "exam/mock.hpp"
#include "exam/questions.hpp"
#include "support.hpp"

using namespace boxes;
using namespace boxes::exam;

namespace {

// A wrong answer of the right form for one answer line.
std::string wrongAnswer(const Part& p) {
    switch (p.type) {
        case AnswerType::YesNo:
            return p.yes ? "no" : "yes";
        case AnswerType::Choice:
            return p.choice == 'a' ? "b" : "a";
        case AnswerType::Words:
            return "I do not know";
        case AnswerType::Order:
            return std::string(p.order.rbegin(), p.order.rend());
        case AnswerType::Numbers:
            break;
    }
    if (p.expected.empty()) return formatNumbers(std::vector<double>(p.count, 0.0));
    std::vector<double> off = p.expected;
    for (double& v : off) v += 1.5;
    return formatNumbers(off);
}

// The answer file: the key's answers for the questions in `right`, wrong ones elsewhere.
std::string answers(const MockSheet& sheet, const std::string& right) {
    std::string out = "# answers\n";
    for (const AnswerSlot& s : answerSlots(sheet)) {
        bool good = right.find(char('0' + s.question->number)) != std::string::npos;
        out += "# " + s.label + "\n" + (good ? s.line->shown : wrongAnswer(*s.line)) + "\n\n";
    }
    return out;
}

std::vector<std::string> lines(const MockSheet& sheet, const std::string& right) {
    std::vector<std::string> v;
    for (const AnswerSlot& s : answerSlots(sheet))
        v.push_back(right.find(char('0' + s.question->number)) != std::string::npos
                        ? s.line->shown
                        : wrongAnswer(*s.line));
    return v;
}

}  // namespace

TEST_SUITE("exam practice") {
    TEST_CASE("mock exam: the form of the example exam and 40 points for many seeds") {
        for (uint64_t seed = 0; seed < 200; ++seed) {
            MockSheet sheet = makeMockSheet(seed);
            INFO("seed " << seed);
            REQUIRE(sheet.questions.size() == 4);
            CHECK(sheet.points() == 40.0);
            std::vector<std::string> letters;
            for (const MockQuestion& q : sheet.questions) {
                CHECK(q.points() == 10.0);
                std::string l;
                for (const MockPart& p : q.parts) {
                    l += p.letter;
                    CHECK_FALSE(p.question.parts.empty());
                    CHECK_FALSE(p.question.solution.empty());
                }
                letters.push_back(l);
            }
            // Question 1 is the example exam's a to e; question 2 its terminology.
            CHECK(letters == std::vector<std::string>{"abcde", "abcde", "abc", "abcde"});
            CHECK(sheet.questions[0].parts[0].question.parts.size() == 4);  // four corners
            CHECK(sheet.questions[1].parts[1].question.parts[0].shown ==
                  "reflection and refraction");
            CHECK(sheet.questions[1].parts[0].question.parts[0].shown == "conservative");
            // The key scores full marks, wrong answers nothing, questions 1 and 2 half.
            CHECK(scoreSheet(sheet, lines(sheet, "1234")).earned == 40.0);
            CHECK(scoreSheet(sheet, lines(sheet, "")).earned == 0.0);
            CHECK(scoreSheet(sheet, lines(sheet, "12")).earned == 20.0);
            // Same seed, same sheet.
            CHECK(answerTemplate(makeMockSheet(seed), true) == answerTemplate(sheet, true));
        }
        CHECK(answerTemplate(makeMockSheet(1), false) != answerTemplate(makeMockSheet(2), false));
    }
    TEST_CASE("mock exam: seed 0 is the example exam's own question 1") {
        MockSheet sheet = makeMockSheet(0);
        const MockQuestion& one = sheet.questions[0];
        CHECK(one.statement.find("E = (1, 1, 1)") != std::string::npos);
        CHECK(one.statement.find("V = (1, 0, 1)") != std::string::npos);
        // c: the plane -x - z = 10 lies behind the eye; d: E is inside the sphere, the ray
        // leaves it at (sqrt(10) - 1, 1, sqrt(10) - 1); e: the normal to the inside.
        CHECK(one.parts[2].question.parts[0].expected.empty());
        const Part& leave = one.parts[3].question.parts[0];
        CHECK(checkAnswer(leave, "sqrt(10)-1, 1, sqrt(10)-1").verdict == Verdict::Correct);
        CHECK(checkAnswer(one.parts[4].question.parts[0], "(-1, 0, -1)/sqrt(2)").verdict ==
              Verdict::Correct);
    }
    TEST_CASE("mock exam: unanswered and skipped and unreadable lines earn nothing") {
        MockSheet sheet = makeMockSheet(5);
        std::vector<std::string> right = lines(sheet, "1234");
        CHECK(scoreSheet(sheet, {}).earned == 0.0);
        std::vector<std::string> some = right;
        some[0] = "skip";
        some[1] = "?";
        some[2] = "(1, 2";  // unreadable
        Score s = scoreSheet(sheet, some);
        CHECK(s.earned == 40.0 - 1.5);  // three of question 1a's four corners, 0.5 each
        CHECK_FALSE(s.lines[0].answered);
        CHECK(s.lines[2].answered);
        CHECK(s.lines[2].checked.verdict == Verdict::Unreadable);
        REQUIRE(s.parts.size() == 18);
        CHECK(s.parts[0].earned == 0.5);
        CHECK(s.parts[0].right == 1);
        CHECK(s.parts[0].lines == 4);
    }
}

TEST_SUITE("exam practice") {
    const std::string program = BOXES_EXAM_PROGRAM;

    TEST_CASE("program: a mock exam answered rightly or wrongly or by half is scored per part") {
        test::TempDir dir;
        MockSheet sheet = makeMockSheet(1);
        for (auto [right, total] : std::vector<std::pair<std::string, std::string>>{
                 {"1234", "Total: 40 of 40 points (100%)"},
                 {"", "Total: 0 of 40 points (0%)"},
                 {"12", "Total: 20 of 40 points (50%)"}}) {
            std::ofstream(dir.file("answers.txt")) << answers(sheet, right);
            auto run =
                test::runProgram(program, "--mock --seed 1 --answers answers.txt --width 0", dir);
            INFO(run.out << run.err);
            REQUIRE(run.exitCode == 0);
            CHECK(run.out.find(total) != std::string::npos);
            // Per part, then the worked solutions with the answers given.
            CHECK(run.out.find("== Score") < run.out.find("== Worked solutions"));
            CHECK(run.out.find(right.empty()
                                   ? "  a      0 / 2   the four corners"
                                   : "  a      2 / 2   the four corners") != std::string::npos);
            CHECK(run.out.find(right == "12"   ? "  c      0 / 5   reflection and refraction"
                               : right.empty() ? "  c      0 / 5"
                                               : "  c      5 / 5") != std::string::npos);
            CHECK(run.out.find(right.empty() ? ", wrong" : ", right)") != std::string::npos);
        }
    }
    TEST_CASE("program: a mock exam's time limit ends it and what is left counts 0") {
        // Answers from a pipe that stays open and sends nothing: the clock ends the exam.
        test::TempDir dir;
        auto run = test::runProgram("/bin/sh",
                                    "-c \"sleep 2 | '" + program +
                                        "' --mock --seed 3 --minutes 0.01 --answers - --width 0\"",
                                    dir);
        INFO(run.out << run.err);
        REQUIRE(run.exitCode == 0);
        CHECK(run.out.find("The time is up.") != std::string::npos);
        CHECK(run.out.find("== Score (the time was up)") != std::string::npos);
        CHECK(run.out.find("Total: 0 of 40 points (0%)") != std::string::npos);
        CHECK(run.out.find("0:01 (minutes:seconds)") != std::string::npos);  // the limit stated
    }
    TEST_CASE("program: the printable sheet and its key and the answer files") {
        test::TempDir dir;
        auto run = test::runProgram(program, "--mock --seed 4 --sheet sheet --no-pdf", dir);
        INFO(run.out << run.err);
        REQUIRE(run.exitCode == 0);
        for (const char* f :
             {"mock-4.html", "mock-4-key.html", "mock-4-answers.txt", "mock-4-key.txt"})
            CHECK(std::filesystem::exists(dir.file(std::string("sheet/") + f)));
        // The key, scored, is full marks; the blank answer file scores nothing.
        auto key = test::runProgram(
            program, "--mock --seed 4 --answers sheet/mock-4-key.txt --width 0", dir);
        CHECK(key.out.find("Total: 40 of 40 points (100%)") != std::string::npos);
        auto blank = test::runProgram(
            program, "--mock --seed 4 --answers sheet/mock-4-answers.txt --width 0", dir);
        CHECK(blank.out.find("Total: 0 of 40 points (0%)") != std::string::npos);
        std::ifstream html(dir.file("sheet/mock-4.html"));
        std::stringstream page;
        page << html.rdbuf();
        CHECK(page.str().find("Question 4 &middot; Vectors, boxes and efficiency") !=
              std::string::npos);
        CHECK(page.str().find("<script") == std::string::npos);
        CHECK(page.str().find("http") == std::string::npos);  // nothing from the network
    }
    TEST_CASE("program: the mock exam's bad input is one line and a non-zero exit") {
        test::TempDir dir;
        for (auto [args, expect] : std::vector<std::pair<std::string, std::string>>{
                 {"--mock --answers missing.txt", "--answers: cannot read 'missing.txt'"},
                 {"--mock --kind vectors", "--kind: the mock exam draws its own kinds"},
                 {"--mock --minutes 0", "--minutes"},
                 {"--mock --minutes abc", "--minutes"},
                 {"--mock --width -3", "--width"},
                 {"--mock --answers x --report none.json", "--report: cannot read 'none.json'"}}) {
            INFO(args);
            auto run = test::runProgram(program, args, dir);
            CHECK(run.exitCode != 0);
            CHECK(test::lineCount(run.err) == 1);
            CHECK(run.err.find(expect) != std::string::npos);
        }
    }
}
