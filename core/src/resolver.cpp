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

namespace {

/// What a path that is not a regular file names, for messages.
const char *file_kind(fs::file_type type) {
    switch (type) {
    case fs::file_type::directory:
        return "a directory";
    case fs::file_type::fifo:
        return "a FIFO";
    case fs::file_type::character:
        return "a character device";
    case fs::file_type::block:
        return "a block device";
    case fs::file_type::socket:
        return "a socket";
    default:
        return "not a file";
    }
}

/// read_file() with an optional size limit of its own (0: only the allocation limit).
std::string read_regular_file(const std::string &path, const std::string &what, size_t max_bytes) {
    // Only regular files: a device (/dev/zero, /dev/urandom) or a FIFO would be read until
    // memory runs out or block forever, a folder fails later with a less clear error.
    std::error_code ec;
    fs::file_status st = fs::status(path, ec);
    if (!fs::exists(st)) FACET_THROW("{}: cannot open \"{}\" (no such file)", what, path);
    if (!fs::is_regular_file(st))
        FACET_THROW("{}: cannot read \"{}\": it is {}, not a regular file", what, path,
                    file_kind(st.type()));
    auto too_large = [&](uintmax_t bytes) {
        FACET_THROW("{}: \"{}\" is {:.1f} MiB, more than the limit of {} MiB", what, path,
                    double(bytes) / double(1 << 20), max_bytes >> 20);
    };
    uintmax_t expected = fs::file_size(path, ec);
    if (!ec && max_bytes > 0 && expected > max_bytes) too_large(expected);
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (!f) FACET_THROW("{}: cannot open \"{}\"", what, path);
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
        if (max_bytes > 0 && data.size() + n > max_bytes) {
            std::fclose(f);
            too_large(data.size() + n);
        }
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

} // namespace

std::string read_file(const std::string &path, const std::string &what) {
    return read_regular_file(path, what, 0);
}

std::string read_file(const std::string &path, const std::string &what, size_t max_bytes) {
    return read_regular_file(path, what, max_bytes);
}

} // namespace facet
