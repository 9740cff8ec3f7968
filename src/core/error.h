// Errors a user can cause (bad config, flag or file): one line saying what is wrong and what was
// expected. Thrown where detected, caught at the CLI / Python boundary and printed as is.
#pragma once

#include <stdexcept>
#include <string>

namespace cradle {

class UserError : public std::runtime_error {
 public:
  explicit UserError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace cradle
