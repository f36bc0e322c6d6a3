#include "exam/answer.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace boxes::exam {

const char* toleranceText() {
    return "numbers are accepted within 0.001, or within 0.1% for large ones";
}

bool withinTolerance(double answer, double expected) {
    if (!std::isfinite(answer)) return false;
    double error = std::abs(answer - expected);
    return error <= kAbsoluteTolerance || error <= kRelativeTolerance * std::abs(expected);
}

namespace {

struct Token {
    enum Kind { Number, Name, Symbol, End } kind = End;
    double value = 0.0;
    std::string text;
    bool spaceBefore = false, spaceAfter = false;
};

std::vector<Token> tokenize(const std::string& s) {
    if (s.size() > kMaxAnswerLength)
        throw std::invalid_argument("the answer is longer than " +
                                    std::to_string(kMaxAnswerLength) + " characters");
    std::vector<Token> tokens;
    size_t i = 0;
    while (i < s.size()) {
        bool space = false;
        while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) {
            ++i;
            space = true;
        }
        if (!tokens.empty() && space) tokens.back().spaceAfter = true;
        if (i >= s.size()) break;
        Token t;
        t.spaceBefore = space;
        char c = s[i];
        if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {
            // from_chars reads decimals only: std::stod read "0x10" as 16.
            auto [ptr, ec] = std::from_chars(s.data() + i, s.data() + s.size(), t.value);
            size_t used = size_t(ptr - (s.data() + i));
            if (ec != std::errc() || used == 0)
                throw std::invalid_argument("could not read a number at '" + s.substr(i) + "'");
            t.kind = Token::Number;
            t.text = s.substr(i, used);
            i += used;
        } else if (std::isalpha(static_cast<unsigned char>(c))) {
            size_t j = i;
            while (j < s.size() && std::isalpha(static_cast<unsigned char>(s[j]))) ++j;
            t.kind = Token::Name;
            t.text = s.substr(i, j - i);
            for (char& ch : t.text) ch = char(std::tolower(static_cast<unsigned char>(ch)));
            i = j;
        } else if (std::string("+-*/^(),;[]").find(c) != std::string::npos) {
            t.kind = Token::Symbol;
            t.text = std::string(1, c == '[' ? '(' : c == ']' ? ')' : c == ';' ? ',' : c);
            ++i;
        } else {
            throw std::invalid_argument(std::string("unexpected character '") + c + "'");
        }
        tokens.push_back(t);
    }
    tokens.push_back(Token{});
    return tokens;
}

// Recursive descent over the tokens; `list` makes whitespace and signs separate numbers.
class Parser {
public:
    Parser(std::vector<Token> tokens, bool list) : tokens_(std::move(tokens)), list_(list) {}

    std::vector<double> parseList() {
        std::vector<double> values;
        while (peek().kind != Token::End) {
            values.push_back(expression());
            if (isSymbol(",")) {
                ++pos_;
                if (peek().kind == Token::End)
                    throw std::invalid_argument("a number is missing after ','");
            }
        }
        return values;
    }

    double parseSingle() {
        double v = expression();
        if (peek().kind != Token::End)
            throw std::invalid_argument("unexpected '" + peek().text + "'");
        return v;
    }

private:
    const Token& peek() const { return tokens_[pos_]; }
    bool isSymbol(const char* s) const { return peek().kind == Token::Symbol && peek().text == s; }
    // In a list at the outer level, " -2" (space before, none after) starts a new number.
    bool startsNewNumber() const {
        return list_ && depth_ == 0 && peek().spaceBefore && !peek().spaceAfter;
    }

    double expression() {
        double v = term();
        while ((isSymbol("+") || isSymbol("-")) && !startsNewNumber()) {
            bool plus = peek().text == "+";
            ++pos_;
            double r = term();
            v = plus ? v + r : v - r;
        }
        return v;
    }

    double term() {
        double v = unary();
        for (;;) {
            if (isSymbol("*") || isSymbol("/")) {
                bool times = peek().text == "*";
                ++pos_;
                double r = unary();
                v = times ? v * r : v / r;
            } else if (!peek().spaceBefore && (peek().kind == Token::Name || isSymbol("("))) {
                v *= power();  // 2sqrt(3), 2(1+1)
            } else {
                return v;
            }
        }
    }

    // Counts the levels of recursion: deeper answers are refused, not a stack overflow.
    struct Nesting {
        int& depth;
        explicit Nesting(int& d) : depth(d) {
            if (++depth > kMaxAnswerNesting)
                throw std::invalid_argument("the answer is nested too deeply");
        }
        ~Nesting() { --depth; }
    };

    double unary() {
        Nesting nesting(nesting_);
        if (isSymbol("-")) {
            ++pos_;
            return -unary();
        }
        if (isSymbol("+")) {
            ++pos_;
            return unary();
        }
        return power();
    }

    double power() {
        double base = primary();
        if (isSymbol("^")) {
            ++pos_;
            return std::pow(base, unary());
        }
        return base;
    }

    double primary() {
        Nesting nesting(nesting_);
        const Token t = peek();
        if (t.kind == Token::Number) {
            ++pos_;
            return t.value;
        }
        if (t.kind == Token::Name) {
            ++pos_;
            if (t.text == "pi") return std::numbers::pi;
            if (t.text == "sqrt") {
                double x = power();
                if (x < 0.0) throw std::invalid_argument("sqrt of a negative number");
                return std::sqrt(x);
            }
            throw std::invalid_argument("unknown word '" + t.text +
                                        "' (numbers, + - * / ^, sqrt, pi)");
        }
        if (isSymbol("(")) {
            ++pos_;
            ++depth_;
            double v = expression();
            if (!isSymbol(")")) throw std::invalid_argument("a ')' is missing");
            --depth_;
            ++pos_;
            return v;
        }
        if (t.kind == Token::End) throw std::invalid_argument("a number is missing at the end");
        throw std::invalid_argument("unexpected '" + t.text + "'");
    }

    std::vector<Token> tokens_;
    bool list_;
    size_t pos_ = 0;
    int depth_ = 0;
    int nesting_ = 0;
};

// The index of the ')' that closes the '(' at `open`, or 0.
size_t matchingClose(const std::vector<Token>& tokens, size_t open) {
    int depth = 0;
    for (size_t i = open; i < tokens.size(); ++i) {
        if (tokens[i].kind != Token::Symbol) continue;
        if (tokens[i].text == "(") ++depth;
        if (tokens[i].text == ")" && --depth == 0) return i;
    }
    return 0;
}

// "(...)" or "[...]" around the whole text is dropped: "(1, 2, 3)" is the list 1, 2, 3.
// Every layer that wraps it all goes, in one copy (erasing layer by layer was quadratic).
std::vector<Token> withoutOuterBrackets(const std::vector<Token>& tokens) {
    size_t begin = 0, end = tokens.size() - 1;  // [begin, end): the tokens before End
    auto isOpen = [&](size_t i) {
        return tokens[i].kind == Token::Symbol && tokens[i].text == "(";
    };
    while (end - begin >= 2 && isOpen(begin) && matchingClose(tokens, begin) == end - 1) {
        ++begin;
        --end;
    }
    if (begin == 0) return tokens;
    std::vector<Token> inner(tokens.begin() + ptrdiff_t(begin), tokens.begin() + ptrdiff_t(end));
    inner.push_back(Token{});
    inner.front().spaceBefore = false;
    return inner;
}

std::vector<Token> slice(const std::vector<Token>& tokens, size_t begin, size_t end) {
    std::vector<Token> part(tokens.begin() + ptrdiff_t(begin), tokens.begin() + ptrdiff_t(end));
    if (!part.empty()) part.front().spaceBefore = false;
    part.push_back(Token{});
    return part;
}

// A vector times or over a number: "(-1, 0, -1)/sqrt(2)", "(1 2 3) * 2", "2 * (1, 2, 3)".
bool scaledVector(const std::vector<Token>& tokens, std::vector<double>& values) {
    auto isSym = [&](size_t i, const char* s) {
        return i < tokens.size() && tokens[i].kind == Token::Symbol && tokens[i].text == s;
    };
    size_t last = tokens.size() - 1;  // the End token
    if (isSym(0, "(")) {
        size_t close = matchingClose(tokens, 0);
        if (close > 0 && close + 2 < last && (isSym(close + 1, "/") || isSym(close + 1, "*"))) {
            std::vector<double> inner = Parser(slice(tokens, 1, close), true).parseList();
            if (inner.size() < 2) return false;
            double k = Parser(slice(tokens, close + 2, last), false).parseSingle();
            for (double& v : inner) v = isSym(close + 1, "/") ? v / k : v * k;
            values = inner;
            return true;
        }
    }
    if (last >= 2 && isSym(last - 1, ")")) {
        for (size_t star = 1; star + 1 < last; ++star) {
            if (!isSym(star, "*") || !isSym(star + 1, "(") ||
                matchingClose(tokens, star + 1) != last - 1)
                continue;
            std::vector<double> inner = Parser(slice(tokens, star + 2, last - 1), true).parseList();
            if (inner.size() < 2) return false;
            double k = Parser(slice(tokens, 0, star), false).parseSingle();
            for (double& v : inner) v *= k;
            values = inner;
            return true;
        }
    }
    return false;
}

}  // namespace

std::vector<double> parseNumberList(const std::string& text) {
    std::vector<Token> tokens = tokenize(text);
    std::vector<double> values;
    if (!scaledVector(tokens, values))
        values = Parser(withoutOuterBrackets(tokens), true).parseList();
    for (double v : values)
        if (!std::isfinite(v))
            throw std::invalid_argument("'" + text + "' has a number that is not finite");
    return values;
}

double evaluateExpression(const std::string& text) {
    Parser parser(tokenize(text), false);
    double v = parser.parseSingle();
    if (!std::isfinite(v)) throw std::invalid_argument("'" + text + "' is not a finite number");
    return v;
}

std::string normalizeWords(const std::string& text) {
    std::string out;
    bool space = false;
    for (char c : text) {
        if (std::isspace(static_cast<unsigned char>(c))) {
            space = !out.empty();
            continue;
        }
        if (space) out += ' ';
        space = false;
        out += char(std::tolower(static_cast<unsigned char>(c)));
    }
    return out;
}

}  // namespace boxes::exam
