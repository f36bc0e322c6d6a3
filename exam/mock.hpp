// A mock exam: a full sheet in the form of the lecture's example exam, seeded, with points
// per part, scored per part. Questions 1 and 2 are the example exam's two questions (its
// first with seeded numbers, or its own with seed 0); 3 and 4 ask the rest of what the
// lecture says the exam expects (light transport; vectors, boxes and efficiency).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "exam/questions.hpp"

namespace boxes::exam {

struct MockPart {
    char letter = 'a';
    std::string topic;  // "the four corners of the virtual screen"
    double points = 0;  // split evenly over the part's answer lines
    Question question;  // its statement, answer lines (parts) and worked solution
};

struct MockQuestion {
    int number = 1;
    std::string title;      // "The camera and one ray (the example exam's question 1)"
    std::string statement;  // givens shared by the parts; may be empty
    std::vector<MockPart> parts;
    double points() const;
};

struct MockSheet {
    uint64_t seed = 0;
    std::string costsSource;  // where the cost question's figures come from
    std::vector<MockQuestion> questions;
    double points() const;
    size_t answerLines() const;
};

// The sheet for one seed: the same seed (and the same measured costs) gives the same sheet.
MockSheet makeMockSheet(uint64_t seed, const MeasuredCosts& costs = referenceCosts());

// One answer line of the sheet, in order: question, part, line.
struct AnswerSlot {
    const MockQuestion* question;
    const MockPart* part;
    const Part* line;
    std::string label;  // "1a", "1a (2 of 4)"
};
std::vector<AnswerSlot> answerSlots(const MockSheet& sheet);

// A typed answer of a mock exam: "skip" or "?" leaves a line unanswered.
bool isSkip(const std::string& answer);

// The marks of one answer line.
struct LineResult {
    bool answered = false;
    std::string answer;
    Checked checked{Verdict::Wrong, ""};
    double points = 0, earned = 0;
};

struct Score {
    std::vector<LineResult> lines;  // one per answer slot
    double earned = 0, total = 0;
    // Per part: earned and possible, in sheet order.
    struct PartScore {
        int question;
        char letter;
        std::string topic;
        double earned, points;
        int right, lines;
    };
    std::vector<PartScore> parts;
};

// Scores the answers given so far (answers[i] for slot i; missing ones are unanswered).
Score scoreSheet(const MockSheet& sheet, const std::vector<std::string>& answers);

// The answer file a student fills in: one line per answer slot, each after a comment naming
// it; `key` fills in the answers (the key a teacher keeps).
std::string answerTemplate(const MockSheet& sheet, bool key);

}  // namespace boxes::exam
