// Sealed files: named byte sections behind a header with their sizes and CRC-32s, written
// atomically (temp file, fsync, rename) and verified whole on read. Checkpoints are sealed files,
// so a truncated, flipped or foreign file is refused with one line instead of loading silently.
//
// Layout (text header, binary payload):
//   CRADLE-SEALED 1\n
//   <sections>\n
//   <name>\t<bytes>\t<crc32 hex>\n      (one line per section)
//   <payload of every section, in order>
//   END <crc32 hex of everything before this line>\n
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>

namespace cradle {

using Sections = std::map<std::string, std::string>;

// CRC-32 (zlib's polynomial) of `bytes`.
std::uint32_t crc32_of(std::string_view bytes);

// Writes `sections` to `file` atomically: "<file>.tmp" is written, flushed to disk and renamed
// over `file`. On any failure (full disk, no permission) the temp file is removed, `file` is left
// as it was and a one-line UserError names the file and the system's reason.
void write_sealed(const std::filesystem::path& file, const Sections& sections);

// Reads and verifies a sealed file. `what` names the kind of file in errors ("checkpoint").
// UserError (one line) for a missing, unreadable, truncated or altered file.
Sections read_sealed(const std::filesystem::path& file, std::string_view what);

// True when the file starts like a sealed file (its first bytes), for clearer errors.
bool looks_sealed(const std::filesystem::path& file);

// Writes bytes to `file` atomically as write_sealed does, without the sealing (for sidecar text
// files such as cut-off log rows).
void write_atomically(const std::filesystem::path& file, std::string_view bytes);

}  // namespace cradle
