// Exam-style questions with seeded random numbers, their answers (from the core's routines
// and the exam's own worked solutions) and a worked solution step by step.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace boxes::exam {

enum class AnswerType {
    Numbers,  // a number or a vector (several numbers); "none" when the question allows it
    YesNo,
    Choice,  // a letter a, b, c, ...
    Words,   // every keyword group must be named
    Order,   // letters in order, "c a b"
};

struct Part {
    std::string prompt;
    AnswerType type = AnswerType::Numbers;
    std::vector<double> expected;  // Numbers: the values; empty: the answer is "none"
    size_t count = 3;              // Numbers: how many values an answer has
    bool noneAllowed = false;      // Numbers: "none" is a possible answer
    bool yes = false;              // YesNo
    char choice = 'a';             // Choice
    std::string order;             // Order: the letters in the right order, "cab"
    std::vector<std::vector<std::string>> keywords;  // Words: one word of every group
    std::string shown;                               // the answer as the solution writes it
};

struct Question {
    std::string kind;
    uint64_t seed = 0;
    std::string statement;
    // The numbers the statement gives, by name, so that tests can re-derive the answers.
    std::map<std::string, std::vector<double>> given;
    std::vector<Part> parts;
    std::vector<std::string> solution;  // the worked solution, one step a line
};

struct QuestionKind {
    std::string name, description;
};

// Every kind of question, in the order --list shows them.
const std::vector<QuestionKind>& questionKinds();

// One operation's time from step 05's table op_cost.
struct OpCost {
    std::string op, type;  // "sqrt", "float"
    double ns = 0.0;       // the median ns per operation
};

// What one run of step 05's lab measured that the kind "cost-order" asks about: the cost of
// each operation of the lecture's list (table op_cost, medians), and the nearest entry of a
// 3600-entry sine table against std::sin in float (table sincos, the fastest samples).
struct MeasuredCosts {
    std::string source;  // where the figures come from, as the question names it
    std::vector<OpCost> ops;
    double tableNs = 0.0, stdSinNs = 0.0;
};

// The figures of one run of step 05 on a 2-thread x86-64 machine, for a student who has not
// run the lab yet (and for printed sheets, the same on every machine).
const MeasuredCosts& referenceCosts();

// The figures of a step 05 report (`05_efficiency --measure --report FILE`, the tour's
// out/05_efficiency.json). Throws std::runtime_error naming what is missing or unreadable.
MeasuredCosts readMeasuredCosts(const std::string& path);

// The question of one kind for one seed (the same seed gives the same numbers). The kind
// "worked-example" is the lecture's example exam's first question, with fixed numbers;
// "cost-order" asks about `costs`. Throws std::invalid_argument for an unknown kind.
Question makeQuestion(const std::string& kind, uint64_t seed,
                      const MeasuredCosts& costs = referenceCosts());

// The lecture's terms that the kind "terminology" asks for (besides the glass and the
// conservative-culling questions), as the solution names them.
std::vector<std::string> terminologyTerms();

enum class Verdict { Correct, Wrong, Unreadable };
struct Checked {
    Verdict verdict;
    std::string note;  // why it is wrong or unreadable
};

// Checks one typed answer against a part (tolerance: answer.hpp).
Checked checkAnswer(const Part& part, const std::string& answer);

// "(1, 2.5, -0.333333)": how the program prints numbers.
std::string formatNumbers(const std::vector<double>& values);

}  // namespace boxes::exam
