#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace facet {

/// Ordered list of folders in which relative file names are looked up.
class FileResolver {
public:
    /// First existing dir/path, or `path` unchanged when it is absolute or nothing matches.
    std::string resolve(const std::string &path) const;
    void prepend(const std::string &dir);
    void append(const std::string &dir);
    const std::vector<std::string> &dirs() const { return m_dirs; }
    void clear() { m_dirs.clear(); }

private:
    std::vector<std::string> m_dirs;
};

/// Whole file as bytes; throws facet::Error "<what>: cannot open \"path\"" (or a read error).
/// Only regular files are read: a folder, a FIFO or a device is refused, saying which it is.
std::string read_file(const std::string &path, const std::string &what);
/// The same, refusing a file larger than `max_bytes` ("<what>: \"path\" is N MiB, more than the
/// limit of M MiB") before reading it, and stopping at that size if it grows while it is read.
std::string read_file(const std::string &path, const std::string &what, size_t max_bytes);

/// The process-wide resolver that plugins use for their file names. The scene loader sets it up
/// (scene folder, <path> entries) while a scene loads.
FileResolver &file_resolver();

} // namespace facet
