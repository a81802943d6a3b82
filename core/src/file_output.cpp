#include "file_output.h"

#include <facet/logger.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <unistd.h>

namespace fs = std::filesystem;

namespace facet::detail {

namespace {

std::string temp_path_for(const std::string &path) {
    fs::path p(path);
    fs::path dir = p.parent_path();
    std::string name = "." + p.filename().string() + ".tmp-" + std::to_string(::getpid());
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

/// Writes `bytes` to the new file `file`, checking every write, the flush to the disk and the
/// close: on a full disk one of them fails (with stdio or an image library's own buffering, the
/// failure can go unnoticed). Returns "" or the reason.
std::string write_bytes(const std::string &file, const std::vector<unsigned char> &bytes) {
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) return std::strerror(errno);
    std::string err;
    size_t done = 0;
    while (err.empty() && done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n > 0)
            done += size_t(n);
        else if (n < 0 && errno == EINTR)
            continue;
        else
            err = n < 0 ? std::strerror(errno) : "no space left";
    }
    // Some file systems (NFS, quotas, delayed allocation) report a full disk only here.
    if (err.empty() && ::fdatasync(fd) != 0 && errno != EINVAL && errno != EROFS)
        err = std::strerror(errno);
    if (::close(fd) != 0 && err.empty()) err = std::strerror(errno);
    return err;
}

} // namespace

void replace_image_file(const std::string &path, const std::vector<unsigned char> &bytes,
                        const std::function<std::string(const std::string &)> &verify) {
    const std::string tmp = temp_path_for(path);
    TempFileGuard guard{tmp};
    const char *kept = fs::exists(path) ? "the existing file is unchanged" : "nothing was written";
    if (std::string err = write_bytes(tmp, bytes); !err.empty())
        FACET_THROW("cannot write image \"{}\": {}; {}", path, err, kept);
    // Nothing replaces the old file unless the new one is complete and reads back.
    std::error_code ec;
    const uintmax_t size = fs::file_size(tmp, ec);
    std::string bad =
        ec ? fmt::format("cannot stat the written file: {}", ec.message())
        : size != bytes.size()
            ? fmt::format("the written file has {} bytes instead of {}", size, bytes.size())
            : verify(tmp);
    if (!bad.empty())
        FACET_THROW("cannot write image \"{}\": {} (disk full?); {}", path, bad, kept);
    if (std::rename(tmp.c_str(), path.c_str()) != 0)
        FACET_THROW("cannot write image \"{}\": renaming the temporary file failed: {}", path,
                    std::strerror(errno));
    guard.armed = false;
}

} // namespace facet::detail
