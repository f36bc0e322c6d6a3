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
};

struct Part {
    std::string prompt;
    AnswerType type = AnswerType::Numbers;
    std::vector<double> expected;  // Numbers: the values; empty: the answer is "none"
    size_t count = 3;              // Numbers: how many values an answer has
    bool noneAllowed = false;      // Numbers: "none" is a possible answer
    bool yes = false;              // YesNo
    char choice = 'a';             // Choice
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

// The question of one kind for one seed (the same seed gives the same numbers). The kind
// "worked-example" is the lecture's example exam's first question, with fixed numbers. Throws std::invalid_argument for an
// unknown kind.
Question makeQuestion(const std::string& kind, uint64_t seed);

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
