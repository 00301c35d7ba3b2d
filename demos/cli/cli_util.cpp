#include "cli_util.hpp"

#include <charconv>
#include <cstdio>
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

}  // namespace dyncull::cli
