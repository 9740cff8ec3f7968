// The valid range of every numeric hyperparameter, declared once by name for all learners, and
// checked when a value is set (Hyperparameters::apply), so a bad value is a one-line error before
// any network exists instead of a LibTorch backtrace or a silent divergence.
#pragma once

#include <string_view>

namespace cradle::learn {

// Throws UserError ("hyperparameter 'gamma' = 2: expected 0 <= gamma <= 1") when `value` lies
// outside `name`'s declared range; any non-finite value is refused. Names without a declared
// range need only be finite.
void check_hyperparameter_range(std::string_view name, double value);

}  // namespace cradle::learn
