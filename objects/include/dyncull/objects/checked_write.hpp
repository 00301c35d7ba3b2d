// Writing files with every write and the close checked: a full disk, a read-only mount or
// /dev/full must come back as an error naming the file, never as a file reported written.
// The one place for this convention; every dyncull writer of CSV, Markdown, PNG and plot
// files goes through it (the binary files stream through BinaryWriter, binary_file.hpp, and check the close here).
#pragma once

#include <filesystem>
#include <fstream>
#include <string_view>

#include "dyncull/objects/error.hpp"

namespace dyncull {

/// Writes `bytes` to `path` (created or truncated), checking the open, every write and the
/// close. On failure the message names the path and the system's reason.
Status writeFileChecked(const std::filesystem::path& path, std::string_view bytes);

/// Opens `stream` (borrowed) for writing `path`; the error names the path and reason.
Status openChecked(std::ofstream& stream, const std::filesystem::path& path);

/// Flushes `stream`, reporting a write that failed since it was opened (e.g. a full disk).
/// For files written in steps (a CSV row per frame), so a failure stops the run early.
Status flushChecked(std::ofstream& stream, const std::filesystem::path& path);

/// Flushes and closes `stream`, reporting any write or close failure since it was opened.
Status closeChecked(std::ofstream& stream, const std::filesystem::path& path);

}  // namespace dyncull
