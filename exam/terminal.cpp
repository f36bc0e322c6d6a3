#include "exam/terminal.hpp"

#include <poll.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <vector>

namespace boxes::exam {

int terminalWidth() {
    winsize w{};
    if (isatty(STDOUT_FILENO) && ioctl(STDOUT_FILENO, TIOCGWINSZ, &w) == 0 && w.ws_col > 0)
        return w.ws_col;
    if (const char* columns = std::getenv("COLUMNS")) {
        int c = std::atoi(columns);
        if (c > 0) return c;
    }
    return 80;
}

namespace {

// The words of one line; spaces inside parentheses are kept inside a word when the whole
// group fits in `limit` characters, so that "(1, 2, 3)" does not break.
std::vector<std::string> words(const std::string& line, size_t limit) {
    std::vector<std::string> out;
    std::string current;
    size_t glueUntil = 0;  // spaces before this index are inside a short group
    for (size_t i = 0; i < line.size(); ++i) {
        char c = line[i];
        if (c == '(' && i >= glueUntil) {
            int depth = 0;
            for (size_t j = i; j < line.size(); ++j) {
                depth += line[j] == '(' ? 1 : line[j] == ')' ? -1 : 0;
                if (depth == 0) {
                    if (j - i + 1 <= limit) glueUntil = j;
                    break;
                }
            }
        }
        if (c == ' ' && i >= glueUntil) {
            if (!current.empty()) out.push_back(current);
            current.clear();
            continue;
        }
        current += c;
    }
    if (!current.empty()) out.push_back(current);
    return out;
}

}  // namespace

std::string wrapText(const std::string& text, int width, int indent) {
    if (width <= 0) return text;
    std::string out;
    std::istringstream lines(text);
    std::string line;
    bool first = true;
    while (std::getline(lines, line)) {
        if (!first) out += '\n';
        first = false;
        size_t lead = line.find_first_not_of(' ');
        if (lead == std::string::npos) continue;
        if (line.size() <= size_t(width)) {  // fits: kept as it is, its spacing too
            out += line;
            continue;
        }
        std::string prefix(lead, ' '), hanging(lead + size_t(indent), ' ');
        size_t limit = size_t(std::max(10, width - int(hanging.size())));
        std::string current = prefix;
        bool empty = true;
        for (const std::string& w : words(line.substr(lead), limit)) {
            if (!empty && current.size() + 1 + w.size() > size_t(width)) {
                out += current + '\n';
                current = hanging + w;
                continue;
            }
            current += (empty ? "" : " ") + w;
            empty = false;
        }
        out += current;
    }
    if (!text.empty() && text.back() == '\n') out += '\n';
    return out;
}

std::string clockText(double seconds) {
    long s = std::max(0L, long(seconds + 0.5));
    char buffer[32];
    if (s >= 3600)
        std::snprintf(buffer, sizeof buffer, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
    else
        std::snprintf(buffer, sizeof buffer, "%ld:%02ld", s / 60, s % 60);
    return buffer;
}

std::string limitText(double minutes) {
    if (minutes >= 1.0 && std::abs(minutes * 10.0 - std::round(minutes * 10.0)) < 1e-9) {
        std::ostringstream s;
        s << minutes << (minutes == 1.0 ? " minute" : " minutes");
        return s.str();
    }
    return clockText(minutes * 60.0) + " (minutes:seconds)";
}

ExamClock::ExamClock(double limitSeconds, bool live)
    : start_(std::chrono::steady_clock::now()), limit_(limitSeconds) {
    if (!live) return;
    running_ = true;
    thread_ = std::thread([this] {
        while (running_) {
            draw();
            for (int i = 0; i < 10 && running_; ++i)
                std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
    });
}

ExamClock::~ExamClock() {
    stop();
}

void ExamClock::stop() {
    if (!running_.exchange(false)) return;
    if (thread_.joinable()) thread_.join();
    // Clear the corner: save the cursor, erase the clock's cells, restore.
    std::string clear =
        "\0337\033[1;" + std::to_string(std::max(1, terminalWidth() - 17)) + "H\033[K\0338";
    (void)!write(STDOUT_FILENO, clear.data(), clear.size());
}

double ExamClock::elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

double ExamClock::left() const {
    return limit_ - elapsed();
}

void ExamClock::draw() const {
    // One write: the terminal's echo of typed keys cannot land between its sequences.
    std::string text = " " + clockText(left()) + " left ";
    int column = std::max(1, terminalWidth() - int(text.size()) + 1);
    std::string s = "\0337\033[1;" + std::to_string(column) + "H\033[7m" + text + "\033[0m\0338";
    (void)!write(STDOUT_FILENO, s.data(), s.size());
}

std::optional<std::string> readLineUntil(int fd, const ExamClock& clock) {
    std::string line;
    for (;;) {
        double left = clock.left();
        if (left <= 0.0) return std::nullopt;
        pollfd p{fd, POLLIN, 0};
        int ready = poll(&p, 1, int(std::min(left, 1.0) * 1000.0) + 1);
        if (ready < 0) return std::nullopt;
        if (ready == 0) continue;
        char c;
        ssize_t n = read(fd, &c, 1);
        if (n <= 0) return line.empty() ? std::nullopt : std::optional<std::string>(line);
        if (c == '\n') {
            if (!line.empty() && line.back() == '\r') line.pop_back();
            return line;
        }
        line += c;
        if (line.size() > 100000) return line;  // a runaway line ends here
    }
}

}  // namespace boxes::exam
