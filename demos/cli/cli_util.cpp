#include "cli_util.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <system_error>

#include <CLI/CLI.hpp>

namespace dyncull::cli {

namespace {
std::string& commandLineStorage() {
    static std::string line;
    return line;
}
}  // namespace

void setCommandLine(int argc, const char* const* argv) {
    std::string& line = commandLineStorage();
    line.clear();
    for (int i = 0; i < argc; ++i) {
        if (i) line += ' ';
        // The program as users call it, not the path it was started from.
        line += i == 0 ? std::string("dyncull") : std::string(argv[i]);
    }
}

const std::string& commandLine() { return commandLineStorage(); }

Expected<glm::ivec2> parseSize(const std::string& text, const std::string& optionName) {
    const Error bad{optionName + ": expected WxH with sides 1..16384 (e.g. 1280x720), got '" + text + "'"};
    const std::size_t x = text.find_first_of("xX");
    if (x == std::string::npos) return bad;
    int w = 0, h = 0;
    const char* b = text.data();
    const char* e = text.data() + text.size();
    auto r1 = std::from_chars(b, b + x, w);
    auto r2 = std::from_chars(b + x + 1, e, h);
    if (r1.ec != std::errc() || r1.ptr != b + x || r2.ec != std::errc() || r2.ptr != e) return bad;
    if (w < 1 || h < 1 || w > 16384 || h > 16384) return bad;
    return glm::ivec2(w, h);
}

CLI::Validator wholeIn(std::uint64_t lo, std::uint64_t hi) {
    const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
    return CLI::Validator(
        [lo, hi, range](std::string& text) -> std::string {
            std::uint64_t v = 0;
            const char* b = text.data();
            const char* e = b + text.size();
            const auto r = std::from_chars(b, e, v);
            const bool digitsOnly = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
            if (!digitsOnly || r.ec != std::errc() || r.ptr != e || v < lo || v > hi)
                return "expected a whole number in " + range + ", got '" + text + "'";
            return {};
        },
        "INT in " + range);
}

CLI::Validator realIn(double lo, double hi, bool lowOpen) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%c%g, %g]", lowOpen ? '(' : '[', lo, hi);
    const std::string range = buf;
    return CLI::Validator(
        [lo, hi, lowOpen, range](std::string& text) -> std::string {
            double v = 0;
            const char* b = text.data();
            const char* e = b + text.size();
            const auto r = std::from_chars(b, e, v);
            const bool inRange = std::isfinite(v) && (lowOpen ? v > lo : v >= lo) && v <= hi;
            if (text.empty() || r.ec != std::errc() || r.ptr != e || !inRange)
                return "expected a finite number in " + range + ", got '" + text + "'";
            return {};
        },
        "NUM in " + range);
}

Status ensureParentDirectory(const std::filesystem::path& file) {
    const std::filesystem::path dir = file.parent_path();
    if (dir.empty()) return {};
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) return Error{dir.string() + ": cannot create directory: " + ec.message()};
    return {};
}

void fail(const std::string& message) {
    std::fprintf(stderr, "error: %s\n", message.c_str());
    throw CLI::RuntimeError(1);
}

std::size_t procStatusBytes(const char* key) {
    std::ifstream f("/proc/self/status");
    std::string line;
    const std::string k(key);
    while (std::getline(f, line))
        if (line.rfind(k, 0) == 0) return std::stoull(line.substr(k.size() + 1)) * 1024;
    return 0;
}

}  // namespace dyncull::cli
