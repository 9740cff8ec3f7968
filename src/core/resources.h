#pragma once
// Where an installed Cradle keeps its data files (configs/, data/teachmyagent/, cradle_figures.py,
// tma_analysis.py): the folder marked by cradle-resources.txt that the running program or Python
// module was installed with. An installed copy uses its own files, never the source tree it was
// built from (which may have moved on or be gone); a build-tree binary has no such folder and its
// callers fall back to the source tree. Header-only so that rooms linking no library of ours
// (tma/) can use it.
//
// The marked folder, from the file holding this code:
//   <site-packages>/cradle/_cradle*.so   -> <site-packages>/cradle   (pip, make install-python)
//   <site-packages>/cradle/bin/cradle    -> <site-packages>/cradle   (pip's `cradle` command)
//   <prefix>/bin/cradle                  -> <prefix>/share/cradle    (make install)
//   build/python/cradle/_cradle*.so      -> build/python/cradle      (links to the source tree)

#include <link.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <system_error>

namespace cradle {

inline constexpr const char* kResourceMarker = "cradle-resources.txt";

namespace detail {

struct ObjectSearch {
  std::uintptr_t address = 0;
  std::string name;
  bool found = false;
};

// The program or shared object whose loaded segments hold `address` ("" for the main program).
inline int find_object(dl_phdr_info* info, size_t, void* data) {
  auto* search = static_cast<ObjectSearch*>(data);
  for (int i = 0; i < info->dlpi_phnum; ++i) {
    const ElfW(Phdr)& segment = info->dlpi_phdr[i];
    if (segment.p_type != PT_LOAD) continue;
    const std::uintptr_t start = info->dlpi_addr + segment.p_vaddr;
    if (search->address >= start && search->address < start + segment.p_memsz) {
      search->name = info->dlpi_name ? info->dlpi_name : "";
      search->found = true;
      return 1;
    }
  }
  return 0;
}

// The file of the program or Python module this code is linked into.
inline std::filesystem::path own_object_file() {
  ObjectSearch search{.address = reinterpret_cast<std::uintptr_t>(&own_object_file)};
  dl_iterate_phdr(find_object, &search);
  std::error_code ec;
  // The main program is listed without a name; the kernel knows its file.
  if (!search.found || search.name.empty())
    return std::filesystem::read_symlink("/proc/self/exe", ec);
  return std::filesystem::weakly_canonical(search.name, ec);
}

}  // namespace detail

// The installed data folder of the running program or module, or nothing for a build-tree binary.
inline const std::optional<std::filesystem::path>& installed_resources() {
  static const std::optional<std::filesystem::path> root =
      []() -> std::optional<std::filesystem::path> {
    const std::filesystem::path dir = detail::own_object_file().parent_path();
    if (dir.empty()) return std::nullopt;
    for (const std::filesystem::path& candidate :
         {dir, dir.parent_path(), dir.parent_path() / "share" / "cradle"}) {
      std::error_code ec;
      if (std::filesystem::is_regular_file(candidate / kResourceMarker, ec)) return candidate;
    }
    return std::nullopt;
  }();
  return root;
}

}  // namespace cradle
