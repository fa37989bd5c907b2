// Hostile configuration files: anything that is not a regular file of at most 1 MiB is refused naming the
// file and why, at once; the text must be one YAML document of UTF-8 without control characters, whose root
// is a mapping; errors are listed up to 50 and echoed values are cut.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <chrono>
#include <filesystem>
#include <random>

#include "base/file_text.hpp"
#include "daemon/config_loader.hpp"
#include "tests/support/process.hpp"

namespace airseg::daemon {
namespace {

using test::TempDir;
using test::write_file;

std::string joined(const ConfigResult& r) {
    std::string out;
    for (const auto& line : r.error_lines()) {
        out += line + "\n";
    }
    return out;
}

/// Loads `path` and fails the test if that takes long enough to have blocked or spun.
ConfigResult timed_load(const std::string& path) {
    const auto started = std::chrono::steady_clock::now();
    auto r = load_config_file(path);
    EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(5)) << path;
    return r;
}

TEST(ConfigHostile, AFileThatIsNotARegularFileIsRefusedAtOnceNamingItAndWhy) {
    TempDir dir;
    ASSERT_EQ(::mkfifo(dir.file("fifo.yaml").c_str(), 0600), 0);
    const std::vector<std::pair<std::string, std::string>> cases{
        {"/dev/zero", "not a regular file (a character device)"},
        {dir.file("fifo.yaml"), "not a regular file (a FIFO)"},
        {dir.path(), "not a regular file (a directory)"},
    };
    for (const auto& [path, why] : cases) {
        const auto r = timed_load(path);
        ASSERT_EQ(r.errors.size(), 1u) << path << "\n" << joined(r);
        EXPECT_EQ(r.errors[0].where, path);
        EXPECT_EQ(r.errors[0].message, "cannot read the configuration file: " + why);
    }
}

TEST(ConfigHostile, ADropInThatIsAFifoOrLinkedToDevZeroIsRefusedNotWaitedFor) {
    TempDir dir;
    write_file(dir.file("airseg.yaml"), "log_level: info\n");
    std::filesystem::create_directory(dir.file("conf.d"));
    ASSERT_EQ(::mkfifo(dir.file("conf.d/10-fifo.yaml").c_str(), 0600), 0);
    std::filesystem::create_symlink("/dev/zero", dir.file("conf.d/20-zero.yaml"));
    std::filesystem::create_directory(dir.file("conf.d/30-dir.yaml"));
    const auto r = timed_load(dir.file("airseg.yaml"));
    ASSERT_EQ(r.errors.size(), 3u) << joined(r);
    EXPECT_EQ(r.errors[0].to_string(),
              dir.file("conf.d/10-fifo.yaml") +
                  ": cannot read the configuration file: not a regular file (a FIFO)");
    EXPECT_NE(r.errors[1].message.find("a character device"), std::string::npos) << joined(r);
    EXPECT_NE(r.errors[2].message.find("a directory"), std::string::npos) << joined(r);
}

TEST(ConfigHostile, AFileOverOneMebibyteIsRefusedWithoutBeingRead) {
    TempDir dir;
    write_file(dir.file("big.yaml"), "log_level: \"" + std::string(10'000'000, 'x') + "\"\n");
    const auto r = timed_load(dir.file("big.yaml"));
    ASSERT_EQ(r.errors.size(), 1u) << joined(r);
    EXPECT_EQ(r.errors[0].message,
              "cannot read the configuration file: larger than the 1 MiB allowed (10000014 bytes)");
}

TEST(ConfigHostile, RandomBytesAreAnErrorNotAValidConfiguration) {
    std::mt19937 random(35);
    for (int i = 0; i < 200; ++i) {
        std::string text(64 + i, '\0');
        for (auto& c : text) {
            c = static_cast<char>(random() & 0xff);
        }
        const auto r = load_config_text(text, "random.yaml");
        EXPECT_FALSE(r.ok()) << "random bytes #" << i << " were accepted";
    }
}

TEST(ConfigHostile, InvalidUtf8AndControlCharactersAreErrorsAtTheirPlace) {
    auto r = load_config_text("log_level: info\nautopilot:\n  port: /dev/tty\xff\n", "u.yaml");
    ASSERT_EQ(r.errors.size(), 1u) << joined(r);
    EXPECT_EQ(r.errors[0].to_string(),
              "u.yaml:3:17: not valid UTF-8 (byte 0xff): a configuration file is UTF-8 text without control "
              "characters");
    // yaml-cpp ends a document at a NUL: the keys after it would be silently ignored.
    r = load_config_text(std::string("log_level: info\0\nthreads: lots\n", 31), "nul.yaml");
    ASSERT_EQ(r.errors.size(), 1u) << joined(r);
    EXPECT_EQ(r.errors[0].where, "nul.yaml:1:16");
    EXPECT_NE(r.errors[0].message.find("a control character (0x00)"), std::string::npos);
    // Escapes put control characters in a value although the text has none.
    r = load_config_text("autopilot:\n  port: \"/dev/tty\\0S1\"\n", "esc.yaml");
    ASSERT_EQ(r.errors.size(), 1u) << joined(r);
    EXPECT_EQ(r.errors[0].key, "autopilot.port");
    EXPECT_NE(r.errors[0].message.find("a control character (0x00) in '/dev/tty\\x00S1'"), std::string::npos)
        << joined(r);
    r = load_config_text("", "set.yaml", {"autopilot.port=/dev/tty\x01"});
    ASSERT_EQ(r.errors.size(), 1u) << joined(r);
    EXPECT_EQ(r.errors[0].where, "--set");
}

// A billion laughs: nine levels of ten aliases. The check for control characters in values must not walk
// them.
TEST(ConfigHostile, AnAliasBombInAValueIsRefusedQuickly) {
    std::string text = "groundlink:\n  ports: &l0 [\"/dev/ttyUSB0\", \"/dev/ttyUSB1\"]\n";
    for (int level = 1; level <= 9; ++level) {
        text += "  l" + std::to_string(level) + ": &l" + std::to_string(level) + " [";
        for (int i = 0; i < 10; ++i) {
            text += std::string(i ? ", " : "") + "*l" + std::to_string(level - 1);
        }
        text += "]\n";
    }
    text += "autopilot:\n  port: *l9\n";
    const auto started = std::chrono::steady_clock::now();
    const auto r = load_config_text(text, "bomb.yaml");
    EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(5));
    EXPECT_FALSE(r.ok());
}

TEST(ConfigHostile, ASecondDocumentAndANonMappingRootAreErrors) {
    auto r = load_config_text("log_level: info\n---\nlog_level: debug\n", "two.yaml");
    ASSERT_EQ(r.errors.size(), 1u) << joined(r);
    EXPECT_EQ(r.errors[0].where.rfind("two.yaml:", 0), 0u) << joined(r);
    EXPECT_NE(r.errors[0].message.find("a second YAML document"), std::string::npos) << joined(r);
    for (const char* root : {"just words\n", "[1, 2]\n", "42\n"}) {
        r = load_config_text(root, "root.yaml");
        ASSERT_EQ(r.errors.size(), 1u) << root << joined(r);
        EXPECT_NE(r.errors[0].message.find("must be a mapping"), std::string::npos) << joined(r);
    }
    EXPECT_TRUE(load_config_text("# only a comment\n", "c.yaml").ok());
    EXPECT_TRUE(load_config_text("log_level: info\n...\n", "end.yaml").ok());  // an end marker alone is fine
}

// Ten thousand here (the system suite has the hundred thousand of the field report, against airsegd itself).
TEST(ConfigHostile, TenThousandUnknownKeysListFiftyErrorsAndCountTheRest) {
    std::string text;
    for (int i = 0; i < 10'000; ++i) {
        text += "k" + std::to_string(i) + ": 1\n";
    }
    const auto r = load_config_text(text, "keys.yaml");
    EXPECT_EQ(r.errors.size(), kMaxListedConfigErrors);
    EXPECT_EQ(r.error_count(), 10'000u);
    const auto lines = r.error_lines();
    ASSERT_EQ(lines.size(), 51u);
    EXPECT_EQ(lines.back(), "... and 9950 more errors");
}

TEST(ConfigHostile, ALongValueIsCutInItsError) {
    const std::string value(200'000, 'v');
    const auto r =
        load_config_text("threads: " + value + "\nautopilot:\n  baud: " + value + "\n", "long.yaml");
    ASSERT_EQ(r.errors.size(), 2u);
    for (const auto& e : r.errors) {
        EXPECT_LT(e.to_string().size(), 200u) << e.to_string().substr(0, 300);
        EXPECT_NE(e.message.find(std::string(80, 'v') + "… (200000 bytes)"), std::string::npos);
    }
    const std::string key(100'000, 'k');
    const auto unknown = load_config_text(key + ": 1\n", "key.yaml");
    ASSERT_EQ(unknown.errors.size(), 1u);
    EXPECT_LT(unknown.errors[0].to_string().size(), 400u);
}

}  // namespace
}  // namespace airseg::daemon
