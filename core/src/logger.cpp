#include <facet/logger.h>

#include <atomic>
#include <cstdio>
#include <mutex>

namespace facet {

namespace {
std::atomic<int> g_level{int(LogLevel::Info)};
std::atomic<size_t> g_warnings{0};
std::mutex g_mutex;

const char *prefix(LogLevel level) {
    switch (level) {
    case LogLevel::Trace:
        return "[T] ";
    case LogLevel::Debug:
        return "[D] ";
    case LogLevel::Info:
        return "[I] ";
    case LogLevel::Warn:
        return "[W] ";
    case LogLevel::Error:
        return "[E] ";
    default:
        return "";
    }
}
} // namespace

std::string Location::to_string() const {
    if (file.empty()) return "";
    return fmt::format("{}:{}:{}", file, line, column);
}

LogLevel Logger::level() { return LogLevel(g_level.load(std::memory_order_relaxed)); }

void Logger::set_level(LogLevel level) { g_level.store(int(level), std::memory_order_relaxed); }

void Logger::log(LogLevel level, const std::string &msg) {
    if (level == LogLevel::Off) return;
    if (level == LogLevel::Warn) ++g_warnings;
    if (level < Logger::level()) return;
    std::string line = prefix(level) + msg + "\n";
    std::lock_guard<std::mutex> lock(g_mutex);
    std::fputs(line.c_str(), stderr);
    std::fflush(stderr);
}

size_t Logger::warning_count() { return g_warnings.load(); }

} // namespace facet
