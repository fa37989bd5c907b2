#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "daemon/cli.hpp"
#include "daemon/config_loader.hpp"
#include "daemon/config_schema.hpp"
#include "daemon/duration.hpp"

namespace airseg::daemon {
namespace {

using std::chrono::milliseconds;

TEST(Duration, ParsesUnitsAndRefusesBareNumbers) {
    EXPECT_EQ(parse_duration("1500ms"), milliseconds(1500));
    EXPECT_EQ(parse_duration("3s"), milliseconds(3000));
    EXPECT_EQ(parse_duration("0.5s"), milliseconds(500));
    EXPECT_EQ(parse_duration("2m"), milliseconds(120'000));
    EXPECT_EQ(parse_duration("1h"), milliseconds(3'600'000));
    EXPECT_FALSE(parse_duration("3"));
    EXPECT_FALSE(parse_duration("-3s"));
    EXPECT_FALSE(parse_duration("s"));
    EXPECT_FALSE(parse_duration("3 s"));
    EXPECT_FALSE(parse_duration("1e400s"));
    EXPECT_EQ(format_duration(milliseconds(1500)), "1500ms");
    EXPECT_EQ(format_duration(milliseconds(3000)), "3s");
    EXPECT_EQ(format_duration(milliseconds(120'000)), "2m");
}

TEST(Config, EmptyFileGivesDefaults) {
    auto r = load_config_text("", "empty.yaml");
    ASSERT_TRUE(r.ok());
    EXPECT_EQ(r.config.autopilot.port, "/dev/ttyACM0");
    EXPECT_EQ(r.config.groundlink.baud, 57600);
    EXPECT_EQ(r.config.status.socket_mode, 0660u);
}

TEST(Config, UnknownKeyIsNamedWithItsLineAndAHint) {
    auto r = load_config_text("threads: 2\nautopilot:\n  prot: /dev/ttyS1\n", "a.yaml");
    ASSERT_EQ(r.errors.size(), 1u);
    EXPECT_EQ(r.errors[0].where, "a.yaml:3:3");
    EXPECT_EQ(r.errors[0].key, "autopilot.prot");
    EXPECT_NE(r.errors[0].message.find("did you mean 'autopilot.port'"), std::string::npos);
}

TEST(Config, AllErrorsOfAFileAreReportedAtOnce) {
    auto r = load_config_text(
        "threads: many\n"
        "log_level: loud\n"
        "autopilot:\n"
        "  baud: 1234\n"
        "  reconnect_min: 5\n"
        "groundlink:\n"
        "  ports: []\n"
        "bogus_key: 1\n",
        "b.yaml");
    ASSERT_EQ(r.errors.size(), 6u);
    std::vector<std::string> keys;
    for (const auto& e : r.errors) {
        keys.push_back(e.key);
    }
    EXPECT_EQ(keys, (std::vector<std::string>{"threads", "log_level", "autopilot.baud",
                                              "autopilot.reconnect_min", "groundlink.ports", "bogus_key"}));
    EXPECT_EQ(r.errors[5].where, "b.yaml:8:1");
}

TEST(Config, RangesAndTypesAreChecked) {
    EXPECT_FALSE(load_config_text("threads: 65\n", "x").ok());
    EXPECT_FALSE(load_config_text("threads: -1\n", "x").ok());
    EXPECT_FALSE(load_config_text("autopilot:\n  reset_on_open: maybe\n", "x").ok());
    EXPECT_FALSE(load_config_text("autopilot:\n  reconnect_max: 2h\n", "x").ok());
    EXPECT_FALSE(load_config_text("autopilot: 3\n", "x").ok());
    EXPECT_FALSE(load_config_text("status:\n  socket_mode: \"0999\"\n", "x").ok());
    EXPECT_TRUE(load_config_text("autopilot:\n  bauds: [115200, 57600]\n", "x").ok());
}

TEST(Config, DuplicateKeysAndSyntaxErrorsHaveLocations) {
    auto dup = load_config_text("threads: 1\nthreads: 2\n", "d.yaml");
    ASSERT_EQ(dup.errors.size(), 1u);
    EXPECT_EQ(dup.errors[0].where, "d.yaml:2:1");
    auto syntax = load_config_text("autopilot:\n  port: [unclosed\n", "s.yaml");
    ASSERT_EQ(syntax.errors.size(), 1u);
    EXPECT_TRUE(syntax.errors[0].where.starts_with("s.yaml:"));
    EXPECT_NE(syntax.errors[0].message.find("YAML syntax error"), std::string::npos);
}

TEST(Config, CrossKeyRulesPointAtTheKey) {
    auto r = load_config_text("groundlink:\n  mode: split\n  ports: [/dev/ttyUSB0]\n", "c.yaml");
    ASSERT_EQ(r.errors.size(), 1u);
    EXPECT_EQ(r.errors[0].where, "c.yaml:3:3");
    EXPECT_EQ(r.errors[0].key, "groundlink.ports");
}

TEST(Config, SetOverridesAreValidatedLikeTheFile) {
    auto ok = load_config_text(
        "", "x",
        {"autopilot.port=/dev/ttyUSB1", "groundlink.ports=[/dev/a, /dev/b]", "groundlink.mode=split"});
    ASSERT_TRUE(ok.ok()) << ok.errors[0].to_string();
    EXPECT_EQ(ok.config.autopilot.port, "/dev/ttyUSB1");
    EXPECT_EQ(ok.config.groundlink.ports.size(), 2u);

    auto bad = load_config_text("", "x", {"autopilot.baud=7", "autopilot.nope=1", "noequals"});
    ASSERT_EQ(bad.errors.size(), 3u);
    EXPECT_EQ(bad.errors[0].where, "--set");
    EXPECT_EQ(bad.errors[0].key, "autopilot.baud");
    EXPECT_EQ(bad.errors[1].key, "autopilot.nope");
}

TEST(Config, ShippedExampleIsValidAndDocumentsEveryKey) {
    const std::string path = std::string(AIRSEG_SOURCE_DIR) + "/config/airseg.yaml";
    auto r = load_config_file(path);
    ASSERT_TRUE(r.ok()) << r.errors[0].to_string();
    const YAML::Node root = YAML::LoadFile(path);
    for (const auto& spec : config_schema()) {
        YAML::Node node = YAML::Clone(root);
        std::string rest = spec.path;
        bool found = true;
        while (found) {
            const auto dot = rest.find('.');
            const std::string part = rest.substr(0, dot);
            if (!node.IsMap() || !node[part]) {
                found = false;
                break;
            }
            node = node[part];
            if (dot == std::string::npos) {
                break;
            }
            rest = rest.substr(dot + 1);
        }
        EXPECT_TRUE(found) << "config/airseg.yaml does not show the key " << spec.path;
    }
    // And it shows the defaults: loading it changes nothing from a default Config.
    EXPECT_TRUE(diff_config(Config{}, r.config).empty());
}

TEST(Config, DiffNamesRuntimeChanges) {
    Config a, b;
    b.log_level = "debug";
    b.autopilot.port = "/dev/ttyS3";
    auto changes = diff_config(a, b);
    ASSERT_EQ(changes.size(), 2u);
    EXPECT_EQ(changes[0].key, "log_level");
    EXPECT_TRUE(changes[0].runtime);
    EXPECT_EQ(changes[1].key, "autopilot.port");
    EXPECT_FALSE(changes[1].runtime);
}

TEST(Cli, BadArgumentsExitTwoWithUsage) {
    const char* argv[] = {"airsegd", "--frobnicate"};
    auto r = parse_cli(2, argv);
    EXPECT_EQ(r.action, CliResult::Action::Exit);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.output.find("Usage: airsegd"), std::string::npos);

    const char* argv2[] = {"airsegd", "--log-level", "loud"};
    EXPECT_EQ(parse_cli(3, argv2).exit_code, 2);
}

TEST(Cli, RepeatedSetKeepsOrder) {
    const char* argv[] = {"airsegd", "--config", "f.yaml", "--set", "a=1", "--set", "b=2", "--check-config"};
    auto r = parse_cli(8, argv);
    ASSERT_EQ(r.action, CliResult::Action::Run);
    EXPECT_EQ(r.options.config_path, "f.yaml");
    EXPECT_TRUE(r.options.check_config);
    EXPECT_EQ(r.options.overrides, (std::vector<std::string>{"a=1", "b=2"}));
}

}  // namespace
}  // namespace airseg::daemon
