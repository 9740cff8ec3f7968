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

// `to` becomes the same file as `from` (a hard link, or a copy where links fail), replacing what
// stood there in one rename; a UserError "cannot write '<to>': <reason>" when that fails.
inline void link_file(const std::filesystem::path& from, const std::filesystem::path& to) {
  const std::filesystem::path tmp = to.string() + ".tmp";
  std::error_code ec;
  std::filesystem::remove(tmp, ec);
  std::filesystem::create_hard_link(from, tmp, ec);
  if (ec)
    std::filesystem::copy_file(from, tmp, std::filesystem::copy_options::overwrite_existing, ec);
  if (!ec) std::filesystem::rename(tmp, to, ec);
  if (ec) throw UserError("cannot write '" + to.string() + "': " + ec.message());
}

}  // namespace cradle
