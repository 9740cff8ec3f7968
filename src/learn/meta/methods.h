// The names of SaMI's methods and the contrastive sampler each uses (the samplers themselves are
// in learn/meta/samplers.h). No LibTorch here: the CLI and the campaigns ask for the names.
#pragma once

#include <span>
#include <string_view>

namespace cradle::learn::meta {

enum class Contrast { kNone, kEnvDiff, kOne, kHalf, kAll };

// "TESAC", "CCM", "SaTESAC", "SaCCM", "SaCCMAll".
std::span<const std::string_view> method_names();
// The method's sampler; UserError naming the accepted methods for another name.
Contrast method_contrast(std::string_view method);
std::string_view contrast_name(Contrast contrast);  // none, env_diff, one, half, all

}  // namespace cradle::learn::meta
