#include "learn/meta/methods.h"

#include <array>
#include <string>

#include "core/error.h"

namespace cradle::learn::meta {
namespace {

constexpr std::array<std::string_view, 5> kMethods = {"TESAC", "CCM", "SaTESAC", "SaCCM",
                                                      "SaCCMAll"};
constexpr std::array<Contrast, 5> kContrasts = {Contrast::kNone, Contrast::kEnvDiff, Contrast::kOne,
                                                Contrast::kHalf, Contrast::kAll};

}  // namespace

std::span<const std::string_view> method_names() { return kMethods; }

Contrast method_contrast(std::string_view method) {
  for (size_t i = 0; i < kMethods.size(); ++i) {
    if (kMethods[i] == method) return kContrasts[i];
  }
  throw UserError("sami: unknown method '" + std::string(method) +
                  "': expected TESAC, CCM, SaTESAC, SaCCM or SaCCMAll");
}

std::string_view contrast_name(Contrast contrast) {
  switch (contrast) {
    case Contrast::kNone:
      return "none";
    case Contrast::kEnvDiff:
      return "env_diff";
    case Contrast::kOne:
      return "one";
    case Contrast::kHalf:
      return "half";
    case Contrast::kAll:
      return "all";
  }
  return "none";
}

}  // namespace cradle::learn::meta
