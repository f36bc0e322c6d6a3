// The exam in a terminal: text wrapped at spaces to the terminal's width (never inside a
// word), a clock in the screen's corner, and answer lines read against a time limit.
#pragma once

#include <atomic>
#include <chrono>
#include <optional>
#include <string>
#include <thread>

namespace boxes::exam {

// The width to wrap at: the terminal's (stdout), else $COLUMNS, else 80.
int terminalWidth();

// Wraps each line of `text` at spaces to `width` columns; continuation lines start with
// `indent` more spaces than the line's own leading ones. A run in parentheses, such as a
// vector "(1, 2, 3)", is kept on one line when it fits. Words longer than the width are
// left whole. width <= 0: unchanged.
std::string wrapText(const std::string& text, int width, int indent = 2);

// "12:05", "1:02:03"
std::string clockText(double seconds);
// A time limit in words: "90 minutes", "1.5 minutes", "0:30 (minutes:seconds)"
std::string limitText(double minutes);

// A time limit, and a clock in the top right corner of a terminal, redrawn every second
// from a thread (when `live`: stdout is a terminal that understands the escape sequences).
class ExamClock {
public:
    ExamClock(double limitSeconds, bool live);
    ~ExamClock();
    ExamClock(const ExamClock&) = delete;
    ExamClock& operator=(const ExamClock&) = delete;

    double elapsed() const;
    double left() const;  // <= 0 when the time is up
    bool up() const { return left() <= 0.0; }
    void stop();  // ends the live clock (and clears it)

private:
    void draw() const;
    std::chrono::steady_clock::time_point start_;
    double limit_;
    std::atomic<bool> running_{false};
    std::thread thread_;
};

// Reads one line from a file descriptor (a terminal or a pipe), waiting at most until the
// clock's time is up. Nothing: the input ended (Ctrl-D) or the time is up (clock.up()).
std::optional<std::string> readLineUntil(int fd, const ExamClock& clock);

}  // namespace boxes::exam
