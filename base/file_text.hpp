#pragma once
// The one way airseg reads a file it is given (configuration, drop-ins, flight plans, the state directory,
// key and password files, the map's pages): only a regular file, never more than a cap, and never blocking. A
// path that names a FIFO, a directory, a device (/dev/zero) or a socket is refused at once, without being
// opened; the file is opened O_NONBLOCK, so that one swapped for a FIFO after the check cannot block either,
// and is checked again on the open descriptor. No read loops without progress.
#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace airseg {

/// The caps of the files airseg reads (docs/reliability.md, "Bounds and caps"); a plan's is the flight plan
/// loader's (kMaxPlanTextBytes).
inline constexpr std::size_t kMaxConfigFileBytes = std::size_t{1}
                                                   << 20;  // airseg.yaml and each conf.d drop-in
inline constexpr std::size_t kMaxSmallFileBytes = 4096;    // key and password files

/// A regular file of at most `max_bytes`, open for reading; or why not. Closed with the object.
class RegularFile {
  public:
    static RegularFile open(const std::string& path, std::size_t max_bytes);

    RegularFile(RegularFile&& other) noexcept;
    RegularFile& operator=(RegularFile&& other) noexcept;
    RegularFile(const RegularFile&) = delete;
    RegularFile& operator=(const RegularFile&) = delete;
    ~RegularFile();

    bool ok() const { return fd_ >= 0; }
    /// Why the file was refused, without its path: "not a regular file (a FIFO)", "larger than the 1 MiB
    /// allowed (4194304 bytes)", "cannot open it: Permission denied". Empty when open.
    const std::string& error() const { return error_; }
    /// The errno of a failed stat or open; 0 when refused for its kind or size.
    int errno_value() const { return errno_; }
    std::uint64_t size() const { return size_; }  // at the open (a /proc file says 0)
    mode_t mode() const { return mode_; }
    std::size_t max_bytes() const { return max_bytes_; }
    /// Reads up to `n` bytes at `offset` (pread: any number of readers at their own offsets); the bytes read,
    /// 0 at the end, -1 with errno set on an error.
    ssize_t read_at(char* into, std::size_t n, std::uint64_t offset) const;

  private:
    RegularFile() = default;
    int fd_ = -1;
    std::string error_;
    int errno_ = 0;
    std::uint64_t size_ = 0;
    mode_t mode_ = 0;
    std::size_t max_bytes_ = 0;
};

struct FileText {
    std::string text;
    std::string error;  // as RegularFile::error(), or "cannot read it: ...", "larger than ... (it grew ...)"
    int errno_value = 0;  // the errno of a failed stat, open or read; 0 when refused for its kind or size
    mode_t mode = 0;      // st_mode of the file that was read
    bool ok() const { return error.empty(); }
};

/// Reads the regular file `path` whole, if it holds at most `max_bytes`.
FileText read_file_text(const std::string& path, std::size_t max_bytes);

/// "a FIFO", "a directory", "a character device", ... for a file type in st_mode.
const char* file_kind(mode_t mode);

/// "1 MiB", "4 KiB", "1000 bytes": a cap as messages and documents name it.
std::string size_text(std::size_t bytes);

}  // namespace airseg
