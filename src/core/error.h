// Errors that reach the user.
//
// Three tiers, as in Drake: internal invariants use assert(); conditions that depend
// on data we produced ourselves throw std::logic_error; anything a user supplied
// (a file, a flag, a model) that is wrong throws UserError, whose message is one line
// naming where the problem is, what was found and what was expected. The CLI prints
// that line and exits non-zero. A simulation that blows up is not an error at all:
// it is a failed rollout with a penalty (see physics/).
#pragma once

#include <stdexcept>
#include <string>

namespace diverse {

class UserError : public std::runtime_error {
 public:
  explicit UserError(const std::string& message) : std::runtime_error(message) {}
};

// "FILE: FIELD: expected EXPECTATION" (the shape every input error takes).
[[noreturn]] void throw_field_error(const std::string& file, const std::string& field,
                                    const std::string& expectation);

}  // namespace diverse
