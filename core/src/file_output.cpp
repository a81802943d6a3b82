#include "file_output.h"

#include <facet/image.h>
#include <facet/logger.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <unistd.h>

namespace fs = std::filesystem;

namespace facet::detail {

namespace {

/// The temporary file a write of `path` goes to: ".NAME.tmp-PID" next to it. A name too long
/// for that (a file name has at most NAME_MAX bytes) keeps the start of NAME and adds a hash of
/// the whole of it, so that two long names still get different temporary files.
std::string temp_path_for(const std::string &path) {
    fs::path p(path);
    fs::path dir = p.parent_path();
    std::string base = p.filename().string();
    const std::string suffix = ".tmp-" + std::to_string(::getpid());
    if (1 + base.size() + suffix.size() > size_t(NAME_MAX)) {
        uint64_t h = 0xcbf29ce484222325ull; // FNV-1a
        for (unsigned char c : base) h = (h ^ c) * 0x100000001b3ull;
        const std::string tag = fmt::format("~{:016x}", h);
        size_t keep = size_t(NAME_MAX) - 1 - tag.size() - suffix.size();
        // Cut at a character boundary of UTF-8, not inside a character.
        while (keep > 0 && (static_cast<unsigned char>(base[keep]) & 0xC0) == 0x80) --keep;
        base = base.substr(0, keep) + tag;
    }
    std::string name = "." + base + suffix;
    return dir.empty() ? name : (dir / name).string();
}

/// Removes the temporary file when the write does not complete.
struct TempFileGuard {
    std::string path;
    bool armed = true;
    ~TempFileGuard() {
        if (armed) std::remove(path.c_str());
    }
};

/// Writes the bytes `write(sink)` gives to the new file `file`, checking every write, the flush
/// to the disk and the close: on a full disk one of them fails (with stdio or an image library's
/// own buffering, the failure can go unnoticed). Returns "" or the reason; `size` is the end of
/// the furthest write.
std::string write_file(const std::string &file, const std::function<void(const ByteSink &)> &write,
                       uint64_t &size) {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) return std::strerror(errno);
    std::string err;
    size = 0;
    ByteSink sink;
    sink.write_at = [&](const void *data, size_t n, uint64_t offset) {
        const char *bytes = static_cast<const char *>(data);
        size_t done = 0;
        while (done < n) {
            const ssize_t k = ::pwrite(fd, bytes + done, n - done, off_t(offset + done));
            if (k > 0)
                done += size_t(k);
            else if (k < 0 && errno == EINTR)
                continue;
            else
                FACET_THROW("{}", k < 0 ? std::strerror(errno) : "no space left");
        }
        size = std::max<uint64_t>(size, offset + n);
    };
    try {
        write(sink);
    } catch (const std::exception &e) {
        err = e.what();
    } catch (...) {
        err = "an unknown error";
    }
    // Some file systems (NFS, quotas, delayed allocation) report a full disk only here.
    if (err.empty() && ::fdatasync(fd) != 0 && errno != EINVAL && errno != EROFS)
        err = std::strerror(errno);
    if (::close(fd) != 0 && err.empty()) err = std::strerror(errno);
    return err;
}

} // namespace

std::string temp_file_for(const std::string &path) { return temp_path_for(path); }

void replace_image_file(const std::string &path, const std::vector<unsigned char> &bytes,
                        const std::function<std::string(const std::string &)> &verify) {
    replace_image_file(
        path, [&](const ByteSink &sink) { sink.write_at(bytes.data(), bytes.size(), 0); }, verify);
}

void replace_image_file(const std::string &path, const std::function<void(const ByteSink &)> &write,
                        const std::function<std::string(const std::string &)> &verify) {
    const std::string tmp = temp_path_for(path);
    TempFileGuard guard{tmp};
    const char *kept = fs::exists(path) ? "the existing file is unchanged" : "nothing was written";
    uint64_t written = 0;
    if (std::string err = write_file(tmp, write, written); !err.empty())
        FACET_THROW("cannot write image \"{}\": {}; {}", path, err, kept);
    // Nothing replaces the old file unless the new one is complete and reads back.
    std::error_code ec;
    const uintmax_t size = fs::file_size(tmp, ec);
    std::string bad = ec ? fmt::format("cannot stat the written file: {}", ec.message())
                      : size != written ? fmt::format("the written file has {} bytes instead of {}",
                                                      size, written)
                                        : verify(tmp);
    if (!bad.empty())
        FACET_THROW("cannot write image \"{}\": {} (disk full?); {}", path, bad, kept);
    if (std::rename(tmp.c_str(), path.c_str()) != 0)
        FACET_THROW("cannot write image \"{}\": renaming the temporary file failed: {}", path,
                    std::strerror(errno));
    guard.armed = false;
}

} // namespace facet::detail

namespace facet {

void check_output_file(const std::string &path) {
    fs::path p(path);
    std::error_code ec;
    if (fs::is_directory(p, ec)) FACET_THROW("cannot write image \"{}\": it is a directory", path);
    if (p.filename().empty()) FACET_THROW("cannot write image \"{}\": it has no file name", path);
    if (p.filename().string().size() > size_t(NAME_MAX))
        FACET_THROW("cannot write image \"{}\": its file name has {} bytes, more than the {} a "
                    "file name can have",
                    path, p.filename().string().size(), NAME_MAX);
    const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
    if (!fs::is_directory(dir, ec))
        FACET_THROW("cannot write image \"{}\": the folder \"{}\" does not exist", path,
                    dir.string());
    const fs::file_status st = fs::status(p, ec);
    if (fs::exists(st) && !fs::is_regular_file(st))
        FACET_THROW("cannot write image \"{}\": it exists and is not a regular file", path);
    // The write creates its temporary file next to the output and renames it: creating that
    // very file proves both (a folder without write permission, a read-only file system, a name
    // too long, ...).
    const std::string tmp = detail::temp_file_for(path);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0)
        FACET_THROW("cannot write image \"{}\": cannot create a file in the folder \"{}\": {}",
                    path, dir.string(), std::strerror(errno));
    ::close(fd);
    std::remove(tmp.c_str());
}

} // namespace facet
