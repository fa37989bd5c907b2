#include "base/file_text.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <utility>

namespace airseg {

namespace {

std::string larger_than(std::size_t max_bytes, const std::string& size) {
    return "larger than the " + size_text(max_bytes) + " allowed (" + size + ")";
}

std::string not_regular(mode_t mode) {
    return std::string("not a regular file (") + file_kind(mode) + ")";
}

}  // namespace

std::string size_text(std::size_t bytes) {
    constexpr std::size_t kMiB = std::size_t{1} << 20;
    if (bytes >= kMiB && bytes % kMiB == 0) {
        return std::to_string(bytes / kMiB) + " MiB";
    }
    if (bytes >= 1024 && bytes % 1024 == 0) {
        return std::to_string(bytes / 1024) + " KiB";
    }
    return std::to_string(bytes) + " bytes";
}

const char* file_kind(mode_t mode) {
    switch (mode & S_IFMT) {
        case S_IFREG:
            return "a regular file";
        case S_IFDIR:
            return "a directory";
        case S_IFIFO:
            return "a FIFO";
        case S_IFCHR:
            return "a character device";
        case S_IFBLK:
            return "a block device";
        case S_IFSOCK:
            return "a socket";
        case S_IFLNK:
            return "a symbolic link";
        default:
            return "of an unknown kind";
    }
}

RegularFile RegularFile::open(const std::string& path, std::size_t max_bytes) {
    RegularFile out;
    out.max_bytes_ = max_bytes;
    const auto fail = [&out](std::string why, int error = 0) -> RegularFile {
        out.error_ = std::move(why);
        out.errno_ = error;
        return std::move(out);
    };
    // Checked before opening: opening a device can do something of its own (a tty, a watchdog device).
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) {
        const int error = errno;
        return fail(std::string("cannot open it: ") + std::strerror(error), error);
    }
    if (!S_ISREG(st.st_mode)) {
        return fail(not_regular(st.st_mode));
    }
    if (static_cast<std::uint64_t>(st.st_size) > max_bytes) {
        return fail(larger_than(max_bytes, std::to_string(st.st_size) + " bytes"));
    }
    const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) {
        const int error = errno;
        return fail(std::string("cannot open it: ") + std::strerror(error), error);
    }
    // The path may name another file since the stat: what counts is the one opened.
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || static_cast<std::uint64_t>(st.st_size) > max_bytes) {
        ::close(fd);
        return fail(S_ISREG(st.st_mode) ? larger_than(max_bytes, std::to_string(st.st_size) + " bytes")
                                        : not_regular(st.st_mode));
    }
    out.fd_ = fd;
    out.size_ = static_cast<std::uint64_t>(st.st_size);
    out.mode_ = st.st_mode;
    return out;
}

RegularFile::RegularFile(RegularFile&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)),
      error_(std::move(other.error_)),
      errno_(other.errno_),
      size_(other.size_),
      mode_(other.mode_),
      max_bytes_(other.max_bytes_) {}

RegularFile& RegularFile::operator=(RegularFile&& other) noexcept {
    if (this != &other) {
        if (fd_ >= 0) {
            ::close(fd_);
        }
        fd_ = std::exchange(other.fd_, -1);
        error_ = std::move(other.error_);
        errno_ = other.errno_;
        size_ = other.size_;
        mode_ = other.mode_;
        max_bytes_ = other.max_bytes_;
    }
    return *this;
}

RegularFile::~RegularFile() {
    if (fd_ >= 0) {
        ::close(fd_);
    }
}

ssize_t RegularFile::read_at(char* into, std::size_t n, std::uint64_t offset) const {
    for (;;) {
        const ssize_t got = ::pread(fd_, into, n, static_cast<off_t>(offset));
        if (got >= 0 || errno != EINTR) {
            return got;
        }
    }
}

FileText read_file_text(const std::string& path, std::size_t max_bytes) {
    FileText out;
    const RegularFile file = RegularFile::open(path, max_bytes);
    if (!file.ok()) {
        out.error = file.error();
        out.errno_value = file.errno_value();
        return out;
    }
    out.mode = file.mode();
    // The size is a hint (0 for a /proc file, stale for one being written): read to the end, at most one byte
    // past the cap.
    out.text.reserve(static_cast<std::size_t>(file.size()));
    char chunk[16384];
    while (out.text.size() <= max_bytes) {
        const std::size_t want = std::min(sizeof chunk, max_bytes + 1 - out.text.size());
        const ssize_t n = file.read_at(chunk, want, out.text.size());
        if (n < 0) {
            const int error = errno;
            out = FileText{};
            out.error = std::string("cannot read it: ") + std::strerror(error);
            out.errno_value = error;
            return out;
        }
        if (n == 0) {
            return out;
        }
        out.text.append(chunk, static_cast<std::size_t>(n));
    }
    out = FileText{};
    out.error = larger_than(max_bytes, "it grew while it was read");
    return out;
}

}  // namespace airseg
