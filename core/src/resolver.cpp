#include <facet/resolver.h>

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

} // namespace facet
