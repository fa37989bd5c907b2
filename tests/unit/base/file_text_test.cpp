// The one reader of whole files: a regular file up to its cap is read; anything else (a FIFO, a directory, a
// device, a socket, a file over the cap) is refused at once with why, and nothing blocks.
#include "base/file_text.hpp"

#include <gtest/gtest.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>

#include "tests/support/process.hpp"

namespace airseg {
namespace {

using test::TempDir;
using test::write_file;

/// Runs `read` and fails the test if it takes longer than a blocking or spinning read would (generous: the
/// reads under test return in microseconds).
FileText timed_read(const std::string& path, std::size_t cap) {
    const auto started = std::chrono::steady_clock::now();
    auto r = read_file_text(path, cap);
    EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(2)) << path;
    return r;
}

TEST(FileText, ARegularFileUpToItsCapIsReadWhole) {
    TempDir dir;
    write_file(dir.file("a"), "hello\n");
    auto r = read_file_text(dir.file("a"), 6);
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_EQ(r.text, "hello\n");
    EXPECT_TRUE(S_ISREG(r.mode));
    write_file(dir.file("empty"), "");
    EXPECT_TRUE(read_file_text(dir.file("empty"), 0).ok());
}

TEST(FileText, AFileOverItsCapIsRefusedNamingTheCap) {
    TempDir dir;
    write_file(dir.file("big"), std::string(1025, 'x'));
    const auto r = read_file_text(dir.file("big"), 1024);
    EXPECT_FALSE(r.ok());
    EXPECT_EQ(r.error, "larger than the 1 KiB allowed (1025 bytes)");
    EXPECT_TRUE(r.text.empty());
}

TEST(FileText, AFifoIsRefusedAtOnceWithoutWaitingForAWriter) {
    TempDir dir;
    ASSERT_EQ(::mkfifo(dir.file("fifo").c_str(), 0600), 0);
    const auto r = timed_read(dir.file("fifo"), kMaxConfigFileBytes);
    EXPECT_FALSE(r.ok());
    EXPECT_EQ(r.error, "not a regular file (a FIFO)");
}

TEST(FileText, DevZeroADirectoryAndASocketAreRefusedAtOnce) {
    const auto zero = timed_read("/dev/zero", kMaxConfigFileBytes);
    EXPECT_EQ(zero.error, "not a regular file (a character device)");
    TempDir dir;
    EXPECT_EQ(timed_read(dir.path(), kMaxConfigFileBytes).error, "not a regular file (a directory)");
    // Through a symbolic link too: what counts is the file it names.
    std::filesystem::create_symlink("/dev/zero", dir.file("zero.yaml"));
    EXPECT_EQ(timed_read(dir.file("zero.yaml"), kMaxConfigFileBytes).error,
              "not a regular file (a character device)");
    const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
    ASSERT_GE(fd, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    const auto path = dir.file("sock");
    ASSERT_LT(path.size(), sizeof addr.sun_path);
    path.copy(addr.sun_path, path.size());
    ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
    EXPECT_EQ(timed_read(path, kMaxConfigFileBytes).error, "not a regular file (a socket)");
    ::close(fd);
}

TEST(FileText, AMissingOrUnreadableFileSaysWhyWithItsErrno) {
    TempDir dir;
    const auto r = read_file_text(dir.file("none"), 10);
    EXPECT_FALSE(r.ok());
    EXPECT_EQ(r.errno_value, ENOENT);
    EXPECT_NE(r.error.find("No such file or directory"), std::string::npos) << r.error;
}

TEST(FileText, AProcFileWhoseSizeSaysZeroIsReadToItsEndWithinTheCap) {
    const auto r = read_file_text("/proc/self/status", 64 * 1024);
    ASSERT_TRUE(r.ok()) << r.error;
    EXPECT_NE(r.text.find("VmRSS"), std::string::npos);
    // The size a /proc file states (0) is no promise: the cap still holds while it is read.
    const auto small = read_file_text("/proc/self/status", 16);
    EXPECT_FALSE(small.ok());
    EXPECT_EQ(small.error, "larger than the 16 bytes allowed (it grew while it was read)");
}

TEST(FileText, ARegularFileOpenedOnceCanBeReadAtAnyOffset) {
    TempDir dir;
    write_file(dir.file("a"), "0123456789");
    const auto file = RegularFile::open(dir.file("a"), 100);
    ASSERT_TRUE(file.ok()) << file.error();
    EXPECT_EQ(file.size(), 10u);
    char buffer[4];
    ASSERT_EQ(file.read_at(buffer, 4, 6), 4);
    EXPECT_EQ(std::string(buffer, 4), "6789");
    EXPECT_EQ(file.read_at(buffer, 4, 10), 0);
    EXPECT_FALSE(RegularFile::open(dir.path(), 100).ok());
}

TEST(FileText, SizesAreNamedAsDocumentsNameThem) {
    EXPECT_EQ(size_text(1u << 20), "1 MiB");
    EXPECT_EQ(size_text(16u << 20), "16 MiB");
    EXPECT_EQ(size_text(4096), "4 KiB");
    EXPECT_EQ(size_text(1000), "1000 bytes");
}

}  // namespace
}  // namespace airseg
