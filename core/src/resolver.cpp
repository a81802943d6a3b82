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
    std::FILE *f = std::fopen(path.c_str(), "rb");
    if (!f) FACET_THROW("{}: cannot open \"{}\"", what, path);
    std::string data;
    char buf[1 << 16];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof(buf), f)) > 0) data.append(buf, n);
    bool failed = std::ferror(f) != 0;
    std::fclose(f);
    if (failed) FACET_THROW("{}: error while reading \"{}\"", what, path);
    return data;
}

} // namespace facet
