// Shared set-up of the fuzz targets: quiet logging, a low allocation limit (so that a size read
// from an input fails with facet::Error long before the fuzzer's memory limit), and a private
// folder for the file an input is written to (the loaders read files, not memory).
#pragma once

#include <facet/checked.h>
#include <facet/logger.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <unistd.h>

namespace facet::fuzz {

/// Allocation limit inside the fuzz targets: 64 MiB, far below libFuzzer's -rss_limit_mb=2048.
constexpr size_t AllocationLimit = size_t(64) << 20;

inline void init() {
    static bool done = [] {
        Logger::set_level(LogLevel::Off);
        set_allocation_limit(AllocationLimit);
        return true;
    }();
    (void)done;
}

/// A folder of this process for input files (in /dev/shm when there is one: no disk I/O).
inline const std::filesystem::path &scratch_dir() {
    static const std::filesystem::path dir = [] {
        std::error_code ec;
        std::filesystem::path base = std::filesystem::is_directory("/dev/shm", ec)
                                         ? std::filesystem::path("/dev/shm")
                                         : std::filesystem::temp_directory_path();
        std::filesystem::path d = base / ("facet-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(d);
        return d;
    }();
    return dir;
}

/// Writes `size` bytes to <scratch>/input<ext> and returns the path.
inline std::string write_input(const uint8_t *data, size_t size, const std::string &ext) {
    std::string path = (scratch_dir() / ("input" + ext)).string();
    std::FILE *f = std::fopen(path.c_str(), "wb");
    if (!f) std::abort();
    if (size > 0 && std::fwrite(data, 1, size, f) != size) std::abort();
    std::fclose(f);
    return path;
}

} // namespace facet::fuzz
