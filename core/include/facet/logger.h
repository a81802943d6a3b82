#pragma once

#include <fmt/format.h>

#include <stdexcept>
#include <string>

namespace facet {

enum class LogLevel { Trace = 0, Debug, Info, Warn, Error, Off };

/// A position in a scene file (1-based line and column); empty when the object was built in code.
struct Location {
    std::string file;
    int line = 0, column = 0;
    bool valid() const { return !file.empty(); }
    /// "scene.xml:12:5"
    std::string to_string() const;
};

/// The one error type of facet. what() is the full message, location included when known.
class Error : public std::runtime_error {
public:
    explicit Error(const std::string &msg) : std::runtime_error(msg) {}
    Error(const Location &loc, const std::string &msg)
        : std::runtime_error(loc.valid() ? loc.to_string() + ": " + msg : msg), m_location(loc),
          m_message(msg) {}
    const Location &location() const { return m_location; }
    /// The message without the location prefix.
    const std::string &message() const { return m_message.empty() ? m_what_fallback() : m_message; }

private:
    const std::string &m_what_fallback() const {
        static thread_local std::string s;
        s = what();
        return s;
    }
    Location m_location;
    std::string m_message;
};

/// Global logger: one line per message on stderr, with a level prefix.
class Logger {
public:
    static LogLevel level();
    static void set_level(LogLevel level);
    static void log(LogLevel level, const std::string &msg);
    /// Number of warnings logged so far (tests use it).
    static size_t warning_count();
};

} // namespace facet

#define FACET_LOG(lvl, ...)                                                                        \
    do {                                                                                           \
        if (::facet::LogLevel::lvl >= ::facet::Logger::level())                                    \
            ::facet::Logger::log(::facet::LogLevel::lvl, fmt::format(__VA_ARGS__));                \
    } while (0)

/// Throw a facet::Error with a formatted message.
#define FACET_THROW(...) throw ::facet::Error(fmt::format(__VA_ARGS__))
/// Throw a facet::Error that carries a scene location.
#define FACET_THROW_AT(loc, ...) throw ::facet::Error((loc), fmt::format(__VA_ARGS__))
