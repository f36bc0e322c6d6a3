// What a starter kit's exercise bodies throw: the tests and the programs name the missing
// exercise instead of failing somewhere far away.
#pragma once

#include <stdexcept>
#include <string>

namespace boxes {

struct NotImplemented : std::logic_error {
    explicit NotImplemented(const std::string& exercise)
        : std::logic_error("exercise " + exercise + " is not implemented yet"),
          exercise(exercise) {}
    std::string exercise;
};

}  // namespace boxes
