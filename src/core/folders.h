// Output folders of a run: made with their parents, or refused in one line.
#pragma once

#include <filesystem>
#include <string>
#include <system_error>

#include "core/error.h"

namespace cradle {

// Makes `folder` and its parents; a UserError "<what> '<folder>': <reason>" when that fails or a
// file stands there (e.g. what = "sami train: cannot create the run folder").
inline void make_folder(const std::filesystem::path& folder, const std::string& what) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec || !std::filesystem::is_directory(folder)) {
    throw UserError(what + " '" + folder.string() +
                    "': " + (ec ? ec.message() : "a file of that name is in the way"));
  }
}

}  // namespace cradle
