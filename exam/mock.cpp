#include "exam/mock.hpp"

#include <algorithm>
#include <stdexcept>

#include "exam/answer.hpp"
#include "exam/kinds.hpp"

namespace boxes::exam {

using namespace gen;

double MockQuestion::points() const {
    double p = 0;
    for (const MockPart& part : parts) p += part.points;
    return p;
}

double MockSheet::points() const {
    double p = 0;
    for (const MockQuestion& q : questions) p += q.points();
    return p;
}

size_t MockSheet::answerLines() const {
    size_t n = 0;
    for (const MockQuestion& q : questions)
        for (const MockPart& p : q.parts) n += p.question.parts.size();
    return n;
}

namespace {

MockPart part(char letter, const std::string& topic, double points, Question q) {
    if (q.parts.empty()) throw std::logic_error("a mock part without answer lines: " + topic);
    return {letter, topic, points, std::move(q)};
}

// A question of one kind, its seed drawn from the sheet's: "--kind K --seed S" repeats it.
Question drawn(Rng& rng, const std::string& kind, const MeasuredCosts& costs) {
    return makeQuestion(kind, uint64_t(rng.pick(0, 999999)), costs);
}

}  // namespace

MockSheet makeMockSheet(uint64_t seed, const MeasuredCosts& costs) {
    Rng rng(seed);
    MockSheet sheet;
    sheet.seed = seed;
    sheet.costsSource = costs.source;

    // 1: the example exam's first question, a to e on one set of givens.
    bool lecture = seed == 0;
    ChainedQuestion one = exampleQuestionOne(rng, lecture);
    MockQuestion q1;
    q1.number = 1;
    q1.title = lecture ? "The camera and one ray (the example exam's question 1, its own numbers)"
                       : "The camera and one ray (the example exam's question 1, other numbers)";
    q1.statement = one.givens.statement;
    char letter = 'a';
    for (auto& [topic, q] : one.parts) {
        q.kind = "example-1";
        q.seed = seed;
        q.given = one.givens.given;
        q1.parts.push_back(part(letter++, topic, 2, std::move(q)));
    }

    // 2: terminology, as the example exam's second question: conservative culling and the
    // two types of scattering of glass, then three more of the lecture's terms.
    MockQuestion q2;
    q2.number = 2;
    q2.title = "Terminology (the example exam's question 2, and three more of the lecture's terms)";
    std::vector<const Term*> others;
    const Term* conservative = nullptr;
    for (const Term& t : terms()) {
        if (t.term == "conservative")
            conservative = &t;
        else
            others.push_back(&t);
    }
    if (!conservative) throw std::logic_error("the term 'conservative' is missing");
    rng.shuffle(others);
    Question term;
    term.kind = "terminology";
    q2.parts.push_back(part('a', "conservative culling", 2, termQuestion(*conservative, term)));
    q2.parts.push_back(part('b', "the two types of scattering of glass", 2, glassQuestion(term)));
    for (int i = 0; i < 3; ++i)
        q2.parts.push_back(part(char('c' + i), "a term of the lecture", 2,
                                termQuestion(*others[size_t(i)], term)));

    // 3: light transport.
    MockQuestion q3;
    q3.number = 3;
    q3.title = "Light transport";
    q3.parts.push_back(part('a', "diffuse shading: N . L and the distance", 3,
                            drawn(rng, "light-shading", costs)));
    q3.parts.push_back(part('b', "a shadow ray", 2, drawn(rng, "shadow-ray", costs)));
    q3.parts.push_back(
        part('c', "reflection and refraction, depth by depth", 5, drawn(rng, "ray-depth", costs)));

    // 4: vectors, boxes and efficiency.
    MockQuestion q4;
    q4.number = 4;
    q4.title = "Vectors, boxes and efficiency";
    q4.parts.push_back(part('a', "vectors", 2, drawn(rng, "vectors", costs)));
    q4.parts.push_back(part('b', "the slab test", 2, drawn(rng, "ray-box", costs)));
    std::string slide = rng.chance(50) ? "slide-union" : "slide-slab";
    q4.parts.push_back(part('c', "what the slide's code returns", 2, drawn(rng, slide, costs)));
    q4.parts.push_back(part('d', "frustum culling", 2, drawn(rng, "frustum-cull", costs)));
    q4.parts.push_back(
        part('e', "the cost of operations, measured", 2, drawn(rng, "cost-order", costs)));

    sheet.questions = {std::move(q1), std::move(q2), std::move(q3), std::move(q4)};
    return sheet;
}

std::vector<AnswerSlot> answerSlots(const MockSheet& sheet) {
    std::vector<AnswerSlot> slots;
    for (const MockQuestion& q : sheet.questions)
        for (const MockPart& p : q.parts) {
            size_t n = p.question.parts.size();
            for (size_t i = 0; i < n; ++i) {
                std::string label = std::to_string(q.number) + p.letter;
                if (n > 1) label += " (" + std::to_string(i + 1) + " of " + std::to_string(n) + ")";
                slots.push_back({&q, &p, &p.question.parts[i], label});
            }
        }
    return slots;
}

bool isSkip(const std::string& answer) {
    std::string a = normalizeWords(answer);
    return a.empty() || a == "skip" || a == "?";
}

Score scoreSheet(const MockSheet& sheet, const std::vector<std::string>& answers) {
    Score s;
    std::vector<AnswerSlot> slots = answerSlots(sheet);
    size_t i = 0;
    for (const MockQuestion& q : sheet.questions)
        for (const MockPart& p : q.parts) {
            Score::PartScore ps{
                q.number, p.letter, p.topic, 0.0, p.points, 0, int(p.question.parts.size())};
            double each = p.points / double(p.question.parts.size());
            for (const Part& line : p.question.parts) {
                LineResult r;
                r.points = each;
                if (i < answers.size() && !isSkip(answers[i])) {
                    r.answered = true;
                    r.answer = answers[i];
                    r.checked = checkAnswer(line, answers[i]);
                    if (r.checked.verdict == Verdict::Correct) {
                        r.earned = each;
                        ++ps.right;
                    }
                }
                ps.earned += r.earned;
                s.lines.push_back(r);
                ++i;
            }
            s.earned += ps.earned;
            s.total += ps.points;
            s.parts.push_back(ps);
        }
    return s;
}

std::string answerTemplate(const MockSheet& sheet, bool key) {
    std::string out = "# Mock exam, seed " + std::to_string(sheet.seed) +
                      (key ? ": the answer key.\n" : ": your answers.\n") +
                      "# One answer a line, in order, under its comment; 'skip' leaves one "
                      "unanswered.\n# Numbers: (1, 2, 3), 1 2 3, sqrt(10)-1, (-1, 0, -1)/sqrt(2); "
                      "'none'; yes or no; letters.\n# Score it: ./workbook exam --mock --seed " +
                      std::to_string(sheet.seed) + " --answers THIS_FILE\n";
    for (const AnswerSlot& s : answerSlots(sheet))
        out +=
            "# " + s.label + ": " + s.line->prompt + "\n" + (key ? s.line->shown : "skip") + "\n";
    return out;
}

}  // namespace boxes::exam
