// Typed answers of the exam practice (exam/answer.cpp parseNumberList, evaluateExpression,
// withinTolerance; exam/questions.cpp checkAnswer, which exam/main.cpp calls on every
// answer line). Each line of the input is one answer, as the program reads them (a '\r'
// before the newline dropped). Promise: a finite result or std::invalid_argument of one
// line; checkAnswer gives a verdict for every part of every kind of question; a list the
// program prints (formatNumbers) reads back within the tolerance.
#include <cmath>
#include <stdexcept>

#include "exam/answer.hpp"
#include "exam/questions.hpp"
#include "fuzz/fuzz_common.hpp"

namespace {

using namespace boxes::exam;

const std::vector<Question>& questions() {
    static const std::vector<Question> all = [] {
        std::vector<Question> q;
        for (const QuestionKind& k : questionKinds()) q.push_back(makeQuestion(k.name, 1));
        return q;
    }();
    return all;
}

void checkLine(const std::string& line) {
    try {
        double v = evaluateExpression(line);
        if (!std::isfinite(v)) boxes::fuzz::fail("a non-finite value accepted from '" + line + "'");
        if (!withinTolerance(v, v)) boxes::fuzz::fail("a value is not within tolerance of itself");
    } catch (const std::invalid_argument& e) {
        boxes::fuzz::checkMessage(e.what());
    }
    try {
        std::vector<double> values = parseNumberList(line);
        for (double v : values)
            if (!std::isfinite(v))
                boxes::fuzz::fail("a non-finite value in a list from '" + line + "'");
        if (!values.empty()) {
            std::string shown = formatNumbers(values);
            std::vector<double> back = parseNumberList(shown);
            if (back.size() != values.size())
                boxes::fuzz::fail("'" + shown + "' reads back as another count of numbers");
            for (size_t i = 0; i < values.size(); ++i)
                if (!withinTolerance(back[i], values[i]))
                    boxes::fuzz::fail("'" + shown + "' reads back as other numbers");
        }
    } catch (const std::invalid_argument& e) {
        boxes::fuzz::checkMessage(e.what());
    }
    for (const Question& q : questions())
        for (const Part& p : q.parts) {
            Checked c = checkAnswer(p, line);
            if (c.verdict == Verdict::Unreadable && c.note.empty())
                boxes::fuzz::fail("an unreadable answer without a reason");
            if (c.note.find('\n') != std::string::npos)
                boxes::fuzz::fail("a note of several lines");
        }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::string text(reinterpret_cast<const char*>(data), size);
    size_t start = 0;
    while (start <= text.size()) {
        size_t end = text.find('\n', start);
        if (end == std::string::npos) end = text.size();
        std::string line = text.substr(start, end - start);
        if (!line.empty() && line.back() == '\r') line.pop_back();
        checkLine(line);
        start = end + 1;
    }
    return 0;
}
