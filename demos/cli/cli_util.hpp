// Helpers shared by CLI subcommands: option parsing, timing, error exit.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>
#include <glm/glm.hpp>

#include "dyncull/objects/error.hpp"

namespace dyncull::cli {

/// Parses "WxH" (e.g. "1280x720"), each side in 1..16384. Error names the option.
Expected<glm::ivec2> parseSize(const std::string& text, const std::string& optionName);

/// Validators for every numeric option, so a bad value is refused with the flag's name
/// before anything is allocated or run. CLI11 alone reads "-1" into an unsigned option as
/// 2^64-1 and "nan" into a float option, and its Range passes NaN.
/// A whole number in [lo, hi]: digits only (no sign, no fraction, no exponent).
CLI::Validator wholeIn(std::uint64_t lo, std::uint64_t hi);
/// A finite real number in [lo, hi], or in (lo, hi] with `lowOpen` (e.g. sizes that must
/// be positive).
CLI::Validator realIn(double lo, double hi, bool lowOpen = false);

/// Creates the parent directory of `file` if needed. Error names the directory.
Status ensureParentDirectory(const std::filesystem::path& file);

/// The command line as typed (argv joined by spaces), recorded by main() so reports can
/// quote exactly what produced them.
void setCommandLine(int argc, const char* const* argv);
const std::string& commandLine();

/// Prints "error: <message>" on stderr and exits the subcommand with code 1.
[[noreturn]] void fail(const std::string& message);

/// A "VmRSS:"/"VmHWM:" line of /proc/self/status in bytes (current and peak resident set),
/// or 0 where there is none (not Linux).
std::size_t procStatusBytes(const char* key);

/// Milliseconds since construction or the last lap().
class Stopwatch {
public:
    double lap() {
        const auto now = std::chrono::steady_clock::now();
        const double ms = std::chrono::duration<double, std::milli>(now - start_).count();
        start_ = now;
        return ms;
    }

private:
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace dyncull::cli
