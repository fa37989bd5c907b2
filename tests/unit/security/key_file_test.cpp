// The pre-shared key file is refused unless only its owner can read it, with an error that says how to fix
// it.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "services/groundlink/link/key_file.hpp"
#include "tests/support/process.hpp"

namespace airseg::groundlink {
namespace {

using test::TempDir;
using test::write_file;

std::string key_file(const TempDir& dir, mode_t mode) {
    const auto path = dir.file("ground.key");
    write_file(path, std::string(64, 'a') + "\n");
    EXPECT_EQ(::chmod(path.c_str(), mode), 0);
    return path;
}

TEST(KeyFile, OwnerOnlyModesAreAccepted) {
    TempDir dir;
    for (mode_t mode : {0600, 0400}) {
        const auto r = read_key_file(key_file(dir, mode));
        ASSERT_TRUE(r.key) << std::oct << mode << ": " << r.error;
        EXPECT_EQ((*r.key)[0], 0xaa);
        EXPECT_EQ((*r.key)[31], 0xaa);
    }
}

TEST(KeyFile, ModesWiderThanOwnerOnlyAreRefusedNamingFileModeAndFix) {
    TempDir dir;
    for (mode_t mode : {0644, 0640, 0604, 0660, 0606, 0610, 0601, 0777}) {
        const auto path = key_file(dir, mode);
        const auto r = read_key_file(path);
        EXPECT_FALSE(r.key) << std::oct << mode;
        char shown[8];
        std::snprintf(shown, sizeof shown, "%04o", static_cast<unsigned>(mode));
        EXPECT_NE(r.error.find(path), std::string::npos) << r.error;
        EXPECT_NE(r.error.find(shown), std::string::npos) << r.error;
        EXPECT_NE(r.error.find("chmod 600"), std::string::npos) << r.error;
    }
}

TEST(KeyFile, MissingAndMalformedFilesAreRefusedNamingTheFile) {
    TempDir dir;
    const auto missing = read_key_file(dir.file("none.key"));
    EXPECT_FALSE(missing.key);
    EXPECT_NE(missing.error.find(dir.file("none.key")), std::string::npos) << missing.error;

    const auto path = dir.file("short.key");
    write_file(path, "abcd\n");
    ASSERT_EQ(::chmod(path.c_str(), 0600), 0);
    const auto r = read_key_file(path);
    EXPECT_FALSE(r.key);
    EXPECT_NE(r.error.find("64 hexadecimal"), std::string::npos) << r.error;
}

// The usual mistake on a vehicle: the key copied as root, read by the service user. The error must say
// permission denied and how to fix it, not that the content is malformed. Root reads any file, so under
// root the read is done by a child that has become nobody.
TEST(KeyFile, AnUnreadableFileSaysPermissionDeniedAndHowToFixIt) {
    TempDir dir;
    const auto path = key_file(dir, 0600);
    int out[2];
    ASSERT_EQ(::pipe(out), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
        ::close(out[0]);
        const bool dropped = ::getuid() != 0 || (::setgid(65534) == 0 && ::setuid(65534) == 0);
        if (::getuid() != 0 || !dropped) {
            // Not root: the owner loses read permission instead.
            (void)::chmod(path.c_str(), 0200);
        }
        const auto r = read_key_file(path);
        const std::string error = dropped ? r.error : "could not drop privileges";
        (void)!::write(out[1], error.data(), error.size());
        ::_exit(r.key ? 1 : 0);
    }
    ::close(out[1]);
    std::string error;
    char buffer[512];
    for (ssize_t n; (n = ::read(out[0], buffer, sizeof buffer)) > 0;) {
        error.append(buffer, static_cast<std::size_t>(n));
    }
    ::close(out[0]);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the key was read: " << error;
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find("permission denied"), std::string::npos) << error;
    EXPECT_NE(error.find("chown airseg"), std::string::npos) << error;
    EXPECT_EQ(error.find("hexadecimal"), std::string::npos) << error;
}

}  // namespace
}  // namespace airseg::groundlink
