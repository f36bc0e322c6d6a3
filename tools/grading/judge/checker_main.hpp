// The case a checker runs, from its environment rather than its command line: without
// bubblewrap another user's `ps` shows every command line (a hidden case's name among them),
// never another user's environment.
#pragma once

#include <doctest/doctest.h>

#include <cstdlib>
#include <utility>

namespace boxes::judge {

inline void applyCaseFilters(doctest::Context& context) {
    const std::pair<const char*, const char*> filters[] = {{"BOXES_JUDGE_FILE", "source-file"},
                                                           {"BOXES_JUDGE_SUITE", "test-suite"},
                                                           {"BOXES_JUDGE_CASE", "test-case"}};
    for (const auto& [variable, option] : filters)
        if (const char* value = std::getenv(variable)) context.setOption(option, value);
}

}  // namespace boxes::judge
