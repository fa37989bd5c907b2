// The configuration as files on a vehicle: local settings in conf.d merged over the packaged file, errors
// naming the file and line they are in, ports that cannot be serial devices, and paths the systemd unit
// cannot write.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>

#include "daemon/cli.hpp"
#include "daemon/config_loader.hpp"
#include "daemon/config_paths.hpp"
#include "tests/support/process.hpp"

namespace airseg::daemon {
namespace {

using test::TempDir;
using test::write_file;

std::string joined(const std::vector<ConfigError>& errors) {
    std::string out;
    for (const auto& e : errors) {
        out += e.to_string() + "\n";
    }
    return out;
}

struct ConfDir {
    TempDir dir;
    std::string main = dir.file("airseg.yaml");
    ConfDir() {
        write_file(main, "log_level: info\nautopilot:\n  port: /dev/ttyACM0\n  baud: 115200\n");
        std::filesystem::create_directory(dir.file("conf.d"));
    }
    void drop_in(const std::string& name, const std::string& text) const {
        write_file(dir.file("conf.d/" + name), text);
    }
};

TEST(ConfigDropIns, AreMergedInNameOrderOverTheMainFile) {
    ConfDir c;
    c.drop_in("20-radio.yaml", "groundlink:\n  ports: [/dev/ttyUSB3]\nlog_level: warn\n");
    c.drop_in("10-port.yaml", "autopilot:\n  port: /dev/ttyUSB1\nlog_level: debug\n");
    c.drop_in("notes.txt", "not: yaml: at all:");  // not a .yaml: ignored
    c.drop_in(".10-port.yaml.swp", "garbage: [");  // an editor's swap file: ignored
    const auto r = load_config_file(c.main);
    ASSERT_TRUE(r.ok()) << joined(r.errors);
    EXPECT_EQ(r.config.autopilot.port, "/dev/ttyUSB1");  // 10- over the main file
    EXPECT_EQ(r.config.autopilot.baud, 115200);          // kept from the main file
    EXPECT_EQ(r.config.groundlink.ports, std::vector<std::string>{"/dev/ttyUSB3"});
    EXPECT_EQ(r.config.log_level, "warn");  // 20- is read last
    EXPECT_EQ(drop_in_files(c.main), (std::vector<std::string>{c.dir.file("conf.d/10-port.yaml"),
                                                               c.dir.file("conf.d/20-radio.yaml")}));
}

TEST(ConfigDropIns, OverridesStillWinAndNoConfDirIsFine) {
    TempDir dir;
    write_file(dir.file("a.yaml"), "log_level: info\n");
    EXPECT_TRUE(drop_in_files(dir.file("a.yaml")).empty());
    const auto r = load_config_file(dir.file("a.yaml"), {"log_level=error"});
    ASSERT_TRUE(r.ok()) << joined(r.errors);
    EXPECT_EQ(r.config.log_level, "error");
}

TEST(ConfigDropIns, ErrorsNameTheDropInFileAndLine) {
    ConfDir c;
    c.drop_in("50-local.yaml", "log_level: info\nautopilot:\n  prot: /dev/ttyUSB1\n");
    c.drop_in("60-broken.yaml", "autopilot: [\n");
    const auto r = load_config_file(c.main);
    ASSERT_EQ(r.errors.size(), 2u) << joined(r.errors);
    EXPECT_EQ(r.errors[0].where, c.dir.file("conf.d/50-local.yaml") + ":3:3");
    EXPECT_NE(r.errors[0].message.find("did you mean 'autopilot.port'"), std::string::npos)
        << joined(r.errors);
    EXPECT_EQ(r.errors[1].where.rfind(c.dir.file("conf.d/60-broken.yaml") + ":", 0), 0u) << joined(r.errors);
}

TEST(ConfigFiles, AnUnreadableFileSaysWhy) {
    TempDir dir;
    const auto r = load_config_file(dir.file("missing.yaml"));
    ASSERT_EQ(r.errors.size(), 1u);
    EXPECT_EQ(r.errors[0].where, dir.file("missing.yaml"));
    EXPECT_NE(r.errors[0].message.find("No such file or directory"), std::string::npos)
        << r.errors[0].message;
}

TEST(ConfigPorts, RelativePathsAreRefusedAtTheirLine) {
    const auto r = load_config_text("autopilot:\n  port: ttyACM0\n", "f.yaml");
    ASSERT_EQ(r.errors.size(), 1u) << joined(r.errors);
    EXPECT_EQ(r.errors[0].where, "f.yaml:2:3");
    EXPECT_EQ(r.errors[0].key, "autopilot.port");
    EXPECT_NE(r.errors[0].message.find("relative path"), std::string::npos);
    const auto radio = load_config_text("groundlink:\n  ports: [radio0]\n", "f.yaml");
    ASSERT_EQ(radio.errors.size(), 1u) << joined(radio.errors);
    EXPECT_EQ(radio.errors[0].key, "groundlink.ports");
}

TEST(ConfigPorts, AnExistingPathThatIsNotADeviceIsRefused) {
    TempDir dir;
    write_file(dir.file("ttyUSB0"), "");
    const auto r = load_config_text("", "f.yaml", {"autopilot.port=" + dir.file("ttyUSB0")});
    ASSERT_EQ(r.errors.size(), 1u) << joined(r.errors);
    EXPECT_EQ(r.errors[0].where, "--set autopilot.port");
    EXPECT_NE(r.errors[0].message.find("not a serial device"), std::string::npos) << r.errors[0].message;
    // A character device passes; a missing one too (a USB adapter may be plugged in later).
    EXPECT_TRUE(load_config_text("", "f.yaml", {"autopilot.port=/dev/null"}).ok());
    EXPECT_TRUE(load_config_text("", "f.yaml", {"autopilot.port=/dev/ttyUSB9"}).ok());
}

TEST(ConfigPorts, TheAutopilotAndARadioOnOneDeviceAreRefused) {
    const auto r = load_config_text(
        "autopilot:\n  port: /dev/ttyUSB0\ngroundlink:\n  ports: [/dev/ttyUSB0]\n", "f.yaml");
    ASSERT_EQ(r.errors.size(), 1u) << joined(r.errors);
    EXPECT_EQ(r.errors[0].where, "f.yaml:4:3");
    EXPECT_NE(r.errors[0].message.find("autopilot's device"), std::string::npos) << r.errors[0].message;
    // Through a symlink too (/dev/serial/by-id/... names the same device).
    TempDir dir;
    std::filesystem::create_symlink("/dev/null", dir.file("by-id-radio"));
    EXPECT_FALSE(
        load_config_text("", "f.yaml",
                         {"autopilot.port=/dev/null", "groundlink.ports=[" + dir.file("by-id-radio") + "]"})
            .ok());
    // In udp mode the radio ports are not opened.
    EXPECT_TRUE(load_config_text(
                    "", "f.yaml",
                    {"autopilot.port=/dev/ttyUSB0", "groundlink.ports=[/dev/ttyUSB0]", "groundlink.mode=udp"})
                    .ok());
}

TEST(ConfigPaths, PathsOutsideTheUnitsDirectoriesAreWarnedAbout) {
    Config c;
    EXPECT_TRUE(unwritable_path_warnings(c).empty());  // the defaults
    c.autopilot.tlog_enabled = true;
    EXPECT_TRUE(unwritable_path_warnings(c).empty());  // /var/log/airseg: the unit's LogsDirectory
    c.autopilot.tlog_path = "/home/pilot/flight.tlog";
    c.state_dir = "/var/lib/airseg-old";
    const auto w = unwritable_path_warnings(c);
    ASSERT_EQ(w.size(), 2u);
    EXPECT_EQ(w[0].key, "state_dir");
    EXPECT_EQ(w[1].key, "autopilot.tlog.path");
    EXPECT_NE(w[1].message.find("ReadWritePaths"), std::string::npos);
}

TEST(ConfigPaths, TheWritableDirectoriesAreTheUnitsOwn) {
    const auto unit = test::read_file(test::source_path("systemd/airsegd.service"));
    const std::map<std::string, std::string> directive{{"/var/lib/airseg", "StateDirectory=airseg"},
                                                       {"/var/log/airseg", "LogsDirectory=airseg"},
                                                       {"/run/airseg", "RuntimeDirectory=airseg"}};
    ASSERT_EQ(unit_writable_dirs().size(), directive.size());
    for (const auto& dir : unit_writable_dirs()) {
        ASSERT_TRUE(directive.count(dir)) << dir;
        EXPECT_NE(unit.find("\n" + directive.at(dir) + "\n"), std::string::npos) << directive.at(dir);
    }
}

TEST(Cli, AMistypedOptionGetsOneLineWithTheNearMissAndTheHelpHint) {
    const char* argv[] = {"airsegd", "--chek-config"};
    const auto r = parse_cli(2, argv);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.output.find("did you mean '--check-config'"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("airsegd --help"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << r.output;  // one line
    const char* level[] = {"airsegd", "--log-level", "wran"};
    EXPECT_NE(parse_cli(3, level).output.find("did you mean 'warn'"), std::string::npos);
}

}  // namespace
}  // namespace airseg::daemon
