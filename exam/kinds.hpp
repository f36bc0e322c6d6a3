// The question generators by file, for the table of kinds (questions.cpp) and the mock exam
// (mock.cpp). Internal to exam/.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "exam/generate.hpp"
#include "exam/questions.hpp"

namespace boxes::exam::gen {

// questions.cpp
Question vectors(Rng& rng, Question q);
Question rayBox(Rng& rng, Question q);
Question frustumCull(Rng& rng, Question q);

// The lecture's terms, each asked by what it means; an answer must name one word of every
// keyword group (lower case, found anywhere in the answer).
struct Term {
    std::string term, question;
    std::vector<std::vector<std::string>> keywords;
    std::string explanation;
};
const std::vector<Term>& terms();
Question termQuestion(const Term& term, Question q);
// The example exam's second question: the two kinds of scattering glass causes.
Question glassQuestion(Question q);

// light.cpp: light transport
Question lightShading(Rng& rng, Question q);
Question shadowRay(Rng& rng, Question q);
Question rayDepth(Rng& rng, Question q);

// example.cpp: the example exam's first question, a to e, on one set of givens. Each part
// is a question of its own (its statement starts with its letter) that continues the
// givens' statement.
struct ChainedQuestion {
    Question givens;  // the statement of the givens, and the numbers by name
    std::vector<std::pair<std::string, Question>> parts;  // topic, part
};
// With `lectureNumbers` the example exam's own numbers: E = (1,1,1), V = (1,0,1), the plane
// -x - z = 10 and the sphere |p - C| = sqrt(20), C = (-1,1,-1); else seeded ones.
ChainedQuestion exampleQuestionOne(Rng& rng, bool lectureNumbers);
Question exampleCorners(Rng& rng, Question q);    // part a alone
Question exampleDirection(Rng& rng, Question q);  // part b alone

// slide_code.cpp: what the lecture's code fragments, as printed, return
Question slideUnion(Rng& rng, Question q);
Question slideSlab(Rng& rng, Question q);

// costs.cpp: the cost of the lecture's expensive operations as a run of step 05 measured them
Question costOrder(Rng& rng, Question q, const MeasuredCosts& costs);

}  // namespace boxes::exam::gen
