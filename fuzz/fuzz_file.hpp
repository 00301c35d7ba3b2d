// Shared by the libFuzzer targets: the loaders read files, so each input is written to a
// per-process scratch file (in /dev/shm when it exists: no disk I/O per iteration),
// removed at exit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace dyncull::fuzz {

/// The per-process scratch directory, created on first use.
inline const std::filesystem::path& scratchDir() {
    static const std::filesystem::path dir = [] {
        const std::filesystem::path base = std::filesystem::exists("/dev/shm") ? "/dev/shm" : std::filesystem::temp_directory_path();
        auto d = base / ("dyncull_fuzz_" + std::to_string(::getpid()));
        std::filesystem::create_directories(d);
        std::atexit([] {
            std::error_code ec;
            std::filesystem::remove_all(scratchDir(), ec);
        });
        return d;
    }();
    return dir;
}

/// Writes `size` bytes to <scratch dir>/input<ext> and returns the path.
inline std::filesystem::path writeInput(const std::uint8_t* data, std::size_t size, const std::string& ext) {
    const auto path = scratchDir() / ("input" + ext);
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    return path;
}

}  // namespace dyncull::fuzz
