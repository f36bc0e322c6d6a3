// Reading typed answers: numbers, vectors and small exact expressions such as sqrt(10)-1.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace boxes::exam {

// Accepted within this absolute error, or this relative error when that is larger.
constexpr double kAbsoluteTolerance = 1e-3;
constexpr double kRelativeTolerance = 1e-3;
const char* toleranceText();
bool withinTolerance(double answer, double expected);

// Typed answers are bounded (a line of 10^6 parentheses would make the reader quadratic
// and its recursion deep): longer or deeper answers are refused.
constexpr size_t kMaxAnswerLength = 1000;  // characters
// Levels of the reader's recursion: a parenthesis, sign, sqrt or ^ inside another takes
// one or two, so this allows about 100 nested parentheses.
constexpr int kMaxAnswerNesting = 200;

// One number written as an expression: decimals (1.5, -2e-3), + - * / ^, parentheses,
// sqrt(x) (also sqrt 2), pi, and a number written before sqrt or ( multiplies (2sqrt(3)).
// Throws std::invalid_argument naming what could not be read.
double evaluateExpression(const std::string& text);

// A list of numbers in a forgiving format: "(1, 2, 3)", "[1; 2; 3]", "1 2 3", "1 -2 3",
// "sqrt(10)-1, 1, sqrt(10)-1". Without commas, whitespace separates the numbers, and a
// sign written right before a number after a space starts a new one ("1 -2" is two
// numbers, "1 - 2" and "1-2" are one). Throws std::invalid_argument.
std::vector<double> parseNumberList(const std::string& text);

// Lower case, trimmed, inner runs of whitespace collapsed to one space.
std::string normalizeWords(const std::string& text);

}  // namespace boxes::exam
