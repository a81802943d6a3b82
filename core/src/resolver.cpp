#include <facet/checked.h>
#include <facet/logger.h>
#include <facet/resolver.h>

#include <cstdio>
#include <filesystem>

namespace facet {

namespace fs = std::filesystem;

std::string FileResolver::resolve(const std::string &path) const {
    fs::path p(path);
    if (path.empty() || p.is_absolute()) return path;
    std::error_code ec;
    for (const auto &dir : m_dirs) {
        fs::path candidate = fs::path(dir) / p;
        if (fs::exists(candidate, ec)) return candidate.string();
    }
    // Relative to the working directory (also what an unmatched name falls back to).
    return path;
}

void FileResolver::prepend(const std::string &dir) { m_dirs.insert(m_dirs.begin(), dir); }

void FileResolver::append(const std::string &dir) { m_dirs.push_back(dir); }

FileResolver &file_resolver() {
    static FileResolver resolver;
    return resolver;
}

std::string read_file(const std::string &path, const std::string &what) {
    // Only regular files: a device (/dev/zero, /dev/urandom) or a FIFO would be read until
    // memory runs out, a folder fails later with a less clear error.
    std::error_code ec;
    fs::file_status st = fs::status(path, ec);
    if (!fs::exists(st)) FACET_THROW("{}: cannot open \"{}\" (no such file)", what, path);
    if (!fs::is_regular_file(st))
        FACET_THROW("{}: cannot read \"{}\": not a regular file", what, path);
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (!f) FACET_THROW("{}: cannot open \"{}\"", what, path);
    uintmax_t expected = fs::file_size(path, ec);
    std::string data;
    if (!ec) {
        try {
            data.reserve(allocation_bytes(size_t(expected), 1, path, "file contents"));
        } catch (...) {
            std::fclose(f);
            throw;
        }
    }
    char buf[1 << 16];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof(buf), f)) > 0) {
        // A file that grows while it is read must not grow without bound either.
        if (data.size() + n > allocation_limit()) {
            std::fclose(f);
            allocation_bytes(data.size() + n, 1, path, "file contents");
        }
        data.append(buf, n);
    }
    bool failed = std::ferror(f) != 0;
    std::fclose(f);
    if (failed) FACET_THROW("{}: error while reading \"{}\"", what, path);
    return data;
}

} // namespace facet
