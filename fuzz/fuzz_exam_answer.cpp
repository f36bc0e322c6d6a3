// Typed answers of the exam practice (exam/answer.cpp parseNumberList, evaluateExpression,
// withinTolerance; exam/questions.cpp checkAnswer, which exam/main.cpp calls on every
// answer line). Each line of the input is one answer, as the program reads them (a '\r'
// before the newline dropped). Promise: a finite result or std::invalid_argument of one
// line; checkAnswer gives a verdict for every part of every kind of question; a list the
// program prints (formatNumbers) reads back within the tolerance.
#include <cmath>
#include <set>
#include <stdexcept>
#include <tuple>

#include "exam/answer.hpp"
#include "exam/questions.hpp"
#include "fuzz/fuzz_common.hpp"

namespace {

using namespace boxes::exam;

// One part of every kind of answer the questions ask (type, count, "none" allowed, with or
// without an expected value): checking every part of every question made runs too slow.
const std::vector<Part>& parts() {
    static const std::vector<Part> all = [] {
        std::vector<Part> found;
        std::set<std::tuple<int, size_t, bool, bool>> seen;
        for (const QuestionKind& k : questionKinds())
            for (const Part& p : makeQuestion(k.name, 1).parts)
                if (seen.insert({int(p.type), p.count, p.noneAllowed, p.expected.empty()}).second)
                    found.push_back(p);
        return found;
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
    std::vector<double> values;
    try {
        values = parseNumberList(line);
    } catch (const std::invalid_argument& e) {
        boxes::fuzz::checkMessage(e.what());
    }
    for (double v : values)
        if (!std::isfinite(v))
            boxes::fuzz::fail("a non-finite value in a list from '" + line + "'");
    if (!values.empty()) {  // what the program prints reads back (no catch: it must)
        std::string shown = formatNumbers(values);
        std::vector<double> back = parseNumberList(shown);
        if (back.size() != values.size())
            boxes::fuzz::fail("'" + shown + "' reads back as another count of numbers");
        for (size_t i = 0; i < values.size(); ++i)
            if (!withinTolerance(back[i], values[i]))
                boxes::fuzz::fail("'" + shown + "' reads back as other numbers");
    }
    for (const Part& p : parts()) {
        Checked c = checkAnswer(p, line);
        if (c.verdict == Verdict::Unreadable && c.note.empty())
            boxes::fuzz::fail("an unreadable answer without a reason");
        if (c.note.find('\n') != std::string::npos) boxes::fuzz::fail("a note of several lines");
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
