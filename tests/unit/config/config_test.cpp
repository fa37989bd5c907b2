#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "daemon/autopilot_commands.hpp"
#include "daemon/autopilot_setup.hpp"
#include "daemon/autopilot_status.hpp"
#include "daemon/cli.hpp"
#include "daemon/config_loader.hpp"
#include "daemon/config_schema.hpp"
#include "daemon/duration.hpp"
#include "services/groundlink/groundlink_service.hpp"
#include "tests/support/tree_paths.hpp"

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
    const std::string path = ::airseg::test::source_dir() + "/config/airseg.yaml";
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

TEST(Config, MavlinkForwardRatesTakeNamesIdsAndADefault) {
    auto r = load_config_text(
        "groundlink:\n  mavlink_forward:\n    enabled: true\n    rates: {ATTITUDE: 4, \"33\": 2, default: "
        "0.5}\n",
        "f.yaml");
    ASSERT_TRUE(r.ok()) << r.errors[0].to_string();
    const auto f = mavlink_forward_setup(r.config);
    EXPECT_TRUE(f.problems.empty());
    EXPECT_TRUE(f.config.enabled);
    EXPECT_EQ(f.config.rate_hz.at(30), 4.0);
    EXPECT_EQ(f.config.rate_hz.at(33), 2.0);
    EXPECT_EQ(f.config.default_hz, 0.5);
    EXPECT_TRUE(autopilot_setup(r.config).service.forward_frames);

    auto bad = load_config_text(
        "groundlink:\n  mavlink_forward:\n    rates: {NO_SUCH_MESSAGE: 1, ATTITUDE: 90}\n", "b.yaml");
    ASSERT_EQ(bad.errors.size(), 2u);
    EXPECT_EQ(bad.errors[0].key, "groundlink.mavlink_forward.rates");
    EXPECT_NE(bad.errors[0].to_string().find("NO_SUCH_MESSAGE"), std::string::npos);
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

const char* const kRadioYaml =
    "groundlink:\n"
    "  radio:\n"
    "    air_speed: 64\n"
    "    ecc: true\n"
    "    packet: 252\n"
    "    packet_overhead: 8\n"
    "    turnaround: 10ms\n"
    "    duplex: full\n"
    "    buffer: 2048\n";

TEST(RadioConfig, SectionLoadsIntoTheProfile) {
    auto r = load_config_text(kRadioYaml, "r.yaml");
    ASSERT_TRUE(r.ok()) << r.errors[0].to_string();
    const auto& p = r.config.groundlink.radio;
    EXPECT_EQ(p.air_speed_kbps, 64u);
    EXPECT_TRUE(p.ecc);
    EXPECT_EQ(p.packet_bytes, 252u);
    EXPECT_EQ(p.packet_overhead, 8u);
    EXPECT_EQ(p.turnaround, milliseconds(10));
    EXPECT_FALSE(p.half_duplex);
    EXPECT_EQ(p.buffer_bytes, 2048u);

    // Not a runtime key: SIGHUP reports it as needing a restart.
    const auto changes = diff_config(Config{}, r.config);
    ASSERT_EQ(changes.size(), 6u);  // packet is the default
    for (const auto& change : changes) {
        EXPECT_TRUE(change.key.starts_with("groundlink.radio.")) << change.key;
        EXPECT_FALSE(change.runtime) << change.key;
    }
    EXPECT_EQ(changes[4].key, "groundlink.radio.duplex");
    EXPECT_EQ(changes[4].from, "half");
    EXPECT_EQ(changes[4].to, "full");
}

TEST(RadioConfig, SetOverridesReachTheProfile) {
    auto r = load_config_text(kRadioYaml, "r.yaml",
                              {"groundlink.radio.packet=32", "groundlink.radio.duplex=half",
                               "groundlink.radio.ecc=off", "groundlink.radio.turnaround=5ms"});
    ASSERT_TRUE(r.ok()) << r.errors[0].to_string();
    EXPECT_EQ(r.config.groundlink.radio.packet_bytes, 32u);
    EXPECT_TRUE(r.config.groundlink.radio.half_duplex);
    EXPECT_FALSE(r.config.groundlink.radio.ecc);
    EXPECT_EQ(r.config.groundlink.radio.turnaround, milliseconds(5));
    EXPECT_EQ(r.config.groundlink.radio.air_speed_kbps, 64u);  // from the file

    auto bad = load_config_text("", "x", {"groundlink.radio.buffer=10"});
    ASSERT_EQ(bad.errors.size(), 1u);
    EXPECT_EQ(bad.errors[0].where, "--set groundlink.radio.buffer");
    EXPECT_EQ(bad.errors[0].key, "groundlink.radio.buffer");
}

TEST(RadioConfig, EachBadKeyIsNamedAtItsLine) {
    auto r = load_config_text(
        "groundlink:\n"
        "  radio:\n"
        "    air_speed: 200000\n"
        "    ecc: maybe\n"
        "    packet: 5000\n"
        "    packet_overhead: 300\n"
        "    turnaround: 200ms\n"
        "    duplex: simplex\n"
        "    buffer: 20000000\n"
        "    power: 20\n",
        "r.yaml");
    std::vector<std::string> keys;
    for (const auto& e : r.errors) {
        keys.push_back(e.key);
    }
    EXPECT_EQ(keys, (std::vector<std::string>{"groundlink.radio.air_speed", "groundlink.radio.ecc",
                                              "groundlink.radio.packet", "groundlink.radio.packet_overhead",
                                              "groundlink.radio.turnaround", "groundlink.radio.duplex",
                                              "groundlink.radio.buffer", "groundlink.radio.power"}));
    ASSERT_EQ(r.errors.size(), 8u);
    EXPECT_EQ(r.errors[0].where, "r.yaml:3:16");
    EXPECT_NE(r.errors[0].message.find("out of range 0..100000"), std::string::npos) << r.errors[0].message;
    EXPECT_NE(r.errors[5].message.find("expected half or full, got 'simplex'"), std::string::npos)
        << r.errors[5].message;
    EXPECT_NE(r.errors[7].message.find("unknown key"), std::string::npos) << r.errors[7].message;

    // The schema's bounds are the profile's: each at its limit loads.
    auto limits = load_config_text(
        "groundlink:\n  radio: {air_speed: 100000, packet: 4096, packet_overhead: 256, turnaround: 100ms, "
        "buffer: 16777216}\n",
        "l.yaml");
    EXPECT_TRUE(limits.ok()) << limits.errors[0].to_string();
}

TEST(RadioConfig, RulesOfTheProfileNameTheKey) {
    auto overhead =
        load_config_text("groundlink:\n  radio:\n    packet: 0\n    packet_overhead: 8\n", "o.yaml");
    ASSERT_EQ(overhead.errors.size(), 1u);
    EXPECT_EQ(overhead.errors[0].key, "groundlink.radio.packet_overhead");
    EXPECT_EQ(overhead.errors[0].where, "o.yaml:4:5");
    EXPECT_EQ(overhead.errors[0].to_string(),
              "o.yaml:4:5: groundlink.radio.packet_overhead: needs packet (the bytes each packet carries)");

    // Within the schema's range, but in the profile's gaps.
    auto packet = load_config_text("groundlink:\n  radio:\n    packet: 4\n", "p.yaml");
    ASSERT_EQ(packet.errors.size(), 1u);
    EXPECT_EQ(packet.errors[0].key, "groundlink.radio.packet");
    EXPECT_EQ(packet.errors[0].where, "p.yaml:3:5");
    EXPECT_NE(packet.errors[0].message.find("must be 0 (no packets) or 8..4096"), std::string::npos)
        << packet.errors[0].message;
    auto buffer = load_config_text("groundlink:\n  radio:\n    buffer: 10\n", "b.yaml");
    ASSERT_EQ(buffer.errors.size(), 1u);
    EXPECT_EQ(buffer.errors[0].key, "groundlink.radio.buffer");
}

TEST(RadioConfig, TransportConfigForAppliesItOnSerialLinksOnly) {
    auto r = load_config_text(kRadioYaml, "r.yaml");
    ASSERT_TRUE(r.ok()) << r.errors[0].to_string();
    groundlink::GroundlinkServiceConfig g;
    g.baud = 57600;
    g.radio = r.config.groundlink.radio;

    const auto serial = groundlink::transport_config_for(g);
    EXPECT_DOUBLE_EQ(serial.link_rate_bytes_per_s, 5760.0);
    EXPECT_DOUBLE_EQ(serial.air_rate_bytes_per_s, 4000.0);  // 64 kbit/s, halved by ECC
    EXPECT_EQ(serial.air_packet_payload, 252u);
    EXPECT_EQ(serial.air_packet_overhead, 8u);
    EXPECT_EQ(serial.air_turnaround, milliseconds(10));
    EXPECT_FALSE(serial.half_duplex);
    EXPECT_EQ(serial.radio_buffer_bytes, 2048u);
    EXPECT_TRUE(serial.validate().empty());
    // The air, net of each 252-byte packet's 8 bytes, is slower than the port: the budgets follow it.
    EXPECT_NEAR(serial.carried_rate_bytes_per_s(), 4000.0 * 252 / 260, 0.01);

    g.mode = "udp";
    const auto udp = groundlink::transport_config_for(g);
    const groundlink::TransportConfig defaults;
    EXPECT_EQ(udp.air_rate_bytes_per_s, 0.0);
    EXPECT_EQ(udp.air_packet_payload, defaults.air_packet_payload);
    EXPECT_EQ(udp.air_packet_overhead, 0u);
    EXPECT_EQ(udp.air_turnaround, defaults.air_turnaround);
    EXPECT_FALSE(udp.half_duplex);
    EXPECT_EQ(udp.radio_buffer_bytes, 0u);

    // The defaults: the air is the serial port, nothing more to pace for.
    g = {};
    const auto plain = groundlink::transport_config_for(g);
    EXPECT_EQ(plain.air_rate_bytes_per_s, 0.0);
    EXPECT_EQ(plain.air_packet_overhead, 0u);
    EXPECT_TRUE(plain.half_duplex);
}

TEST(AutopilotConfig, KeysReachTheServiceConfiguration) {
    auto r = load_config_text(
        "autopilot:\n"
        "  board: apm2\n"
        "  port: /dev/ttyS4\n"
        "  bauds: [57600, 115200]\n"
        "  boot_timeout: 12s\n"
        "  heartbeat_timeout: 2s\n"
        "  mode_timeout: 800ms\n"
        "  params: {WP_RADIUS: 2.5, CRUISE_SPEED: 1}\n"
        "  streams: {position: 5, extra1: 2}\n"
        "  rc_override: {rate_hz: 20, input_timeout: 300ms}\n"
        "  tlog: {enabled: true, path: /tmp/a.tlog, max_bytes: 100000, keep: 2}\n"
        "  reset: {line: \"gpiochip1:17\", unresponsive_timeout: 9s, max_pulses: 5}\n",
        "k.yaml");
    ASSERT_TRUE(r.ok()) << r.errors[0].to_string();
    const auto setup = autopilot_setup(r.config);
    ASSERT_TRUE(setup.problems.empty());
    const auto& s = setup.service;
    EXPECT_EQ(s.port.serial.path, "/dev/ttyS4");
    EXPECT_EQ(s.port.serial.baud, 57600u);
    EXPECT_EQ(s.autopilot.bauds, (std::vector<unsigned>{57600, 115200}));
    EXPECT_TRUE(s.autopilot.reset_on_open);  // auto on apm2
    EXPECT_EQ(s.autopilot.boot_timeout, std::chrono::seconds(12));
    EXPECT_EQ(s.autopilot.heartbeat_timeout, std::chrono::seconds(2));
    EXPECT_EQ(s.autopilot.mode_timeout, std::chrono::milliseconds(800));
    ASSERT_EQ(s.autopilot.params.size(), 2u);
    EXPECT_EQ(s.autopilot.params[1].name, "WP_RADIUS");
    EXPECT_EQ(s.autopilot.params[1].value, 2.5);
    ASSERT_EQ(s.autopilot.stream_rates.size(), 2u);
    EXPECT_EQ(s.autopilot.stream_rates[0].stream, autopilot::DataStream::Extra1);
    EXPECT_EQ(s.autopilot.stream_rates[1].hz, 5u);
    EXPECT_EQ(s.autopilot.rc_override.rate_hz, 20.0);
    EXPECT_EQ(s.autopilot.rc_override.input_timeout, std::chrono::milliseconds(300));
    EXPECT_TRUE(s.tlog.enabled);
    EXPECT_EQ(s.tlog.path, "/tmp/a.tlog");
    EXPECT_EQ(s.tlog.max_bytes, 100000u);
    EXPECT_EQ(s.tlog.keep, 2u);
    ASSERT_TRUE(s.reset_line);
    EXPECT_EQ(s.reset_line->chip, "gpiochip1");
    EXPECT_EQ(s.reset_line->offset, 17u);
    EXPECT_EQ(s.autopilot.unresponsive_timeout, std::chrono::seconds(9));
    EXPECT_EQ(s.autopilot.max_reset_pulses, 5u);
}

TEST(AutopilotConfig, BoardDefaultsApplyUnlessGiven) {
    auto pix = load_config_text("autopilot:\n  board: pixhawk\n  reset:\n    line: APM_RESET\n", "p");
    ASSERT_TRUE(pix.ok());
    const auto s = autopilot_setup(pix.config).service;
    EXPECT_FALSE(s.autopilot.reset_on_open);
    EXPECT_EQ(s.autopilot.mavlink_version, 2);
    ASSERT_TRUE(s.reset_line);
    EXPECT_EQ(s.reset_line->line_name, "APM_RESET");
    EXPECT_TRUE(s.reset_line->chip.empty());

    auto forced = load_config_text("autopilot:\n  board: pixhawk\n  reset_on_open: \"true\"\n", "p");
    ASSERT_TRUE(forced.ok());
    EXPECT_TRUE(autopilot_setup(forced.config).service.autopilot.reset_on_open);
    EXPECT_FALSE(autopilot_setup(Config{}).service.reset_line) << "no reset line by default";
}

TEST(AutopilotConfig, MessageRatesBaudProbeAndStatusLed) {
    auto r = load_config_text(
        "autopilot:\n"
        "  board: pixhawk\n"
        "  bauds: [57600, 115200]\n"
        "  baud_probe: 1500ms\n"
        "  message_rates: {ATTITUDE: 10, GLOBAL_POSITION_INT: 0}\n"
        "status_led: {line: \"gpiochip0:18\", active_low: true}\n",
        "m.yaml");
    ASSERT_TRUE(r.ok()) << r.errors[0].to_string();
    const auto setup = autopilot_setup(r.config);
    ASSERT_TRUE(setup.problems.empty()) << setup.problems[0];
    const auto& ap = setup.service.autopilot;
    EXPECT_EQ(ap.baud_probe, std::chrono::milliseconds(1500));
    ASSERT_EQ(ap.message_rates.size(), 2u);
    EXPECT_EQ(ap.message_rates[0].msgid, 30u);  // ATTITUDE (the map is ordered by name)
    EXPECT_DOUBLE_EQ(ap.message_rates[0].hz, 10.0);
    EXPECT_EQ(ap.message_rates[1].msgid, 33u);  // GLOBAL_POSITION_INT
    EXPECT_DOUBLE_EQ(ap.message_rates[1].hz, 0.0);
    ASSERT_TRUE(setup.status_led);
    EXPECT_EQ(setup.status_led->chip, "gpiochip0");
    EXPECT_EQ(setup.status_led->offset, 18u);
    EXPECT_TRUE(setup.status_led->active_low);
    EXPECT_FALSE(autopilot_setup(Config{}).status_led) << "no LED by default";

    auto bad = load_config_text("autopilot:\n  message_rates: {ATTITUDE: 4, NO_SUCH_MESSAGE: 1}\n", "n.yaml");
    ASSERT_FALSE(bad.ok());
    EXPECT_EQ(bad.errors[0].key, "autopilot.message_rates");
    EXPECT_NE(bad.errors[0].message.find("NO_SUCH_MESSAGE"), std::string::npos) << bad.errors[0].message;
}

TEST(AutopilotConfig, AutopilotRulesAreReportedAtTheirKeyAndLine) {
    auto r = load_config_text(
        "autopilot:\n"
        "  boot_timeout: 200s\n"
        "  rc_override:\n"
        "    rate_hz: 80\n"
        "  params: {THIS_NAME_IS_TOO_LONG: 1}\n",
        "v.yaml");
    ASSERT_EQ(r.errors.size(), 3u) << r.errors[0].to_string();
    EXPECT_EQ(r.errors[0].key, "autopilot.boot_timeout");
    EXPECT_EQ(r.errors[0].where, "v.yaml:2:3");
    EXPECT_NE(r.errors[0].message.find("outside 1..120"), std::string::npos) << r.errors[0].message;
    EXPECT_EQ(r.errors[1].key, "autopilot.params");
    EXPECT_EQ(r.errors[1].where, "v.yaml:5:3");
    EXPECT_EQ(r.errors[2].key, "autopilot.rc_override.rate_hz");
    EXPECT_EQ(r.errors[2].where, "v.yaml:4:5");

    auto set = load_config_text("", "x", {"autopilot.reset.max_pulses=30"});
    ASSERT_EQ(set.errors.size(), 1u);
    EXPECT_EQ(set.errors[0].where, "--set autopilot.reset.max_pulses");
}

TEST(AutopilotConfig, MapsAreCheckedEntryByEntry) {
    auto bad_stream = load_config_text("autopilot:\n  streams: {positon: 4}\n", "m");
    ASSERT_EQ(bad_stream.errors.size(), 1u);
    EXPECT_NE(bad_stream.errors[0].message.find("unknown name 'positon'"), std::string::npos);
    EXPECT_FALSE(load_config_text("autopilot:\n  streams: {position: 2.5}\n", "m").ok());
    EXPECT_FALSE(load_config_text("autopilot:\n  params: {WP_RADIUS: wide}\n", "m").ok());
    EXPECT_FALSE(load_config_text("autopilot:\n  params: [WP_RADIUS]\n", "m").ok());
    auto over = load_config_text("", "m", {"autopilot.params={WP_RADIUS: 3}"});
    ASSERT_TRUE(over.ok());
    EXPECT_EQ(over.config.autopilot.params.at("WP_RADIUS"), 3.0);
    Config changed;
    changed.autopilot.params["WP_RADIUS"] = 3;
    const auto d = diff_config(Config{}, changed);
    ASSERT_EQ(d.size(), 1u);
    EXPECT_EQ(d[0].to, "{WP_RADIUS: 3}");
}

TEST(AutopilotStatus, SectionCarriesTheDocumentedKeys) {
    autopilot::AutopilotStatus s;
    s.link_up = true;
    s.ready = true;
    s.ready_s = 4.26;
    s.state = autopilot::VehicleState::Parking;
    s.mode = "HOLD";
    s.position = autopilot::Position{41.3, 2.1, 10};
    s.mission_current = 3;
    s.reboots = 1;
    s.link_losses = 4;
    s.link_verdicts_deferred = 5;
    s.syncs = 2;
    s.reconnects = 2;
    const auto j = autopilot_status_json(s);
    EXPECT_EQ(j["link"], "up");
    EXPECT_EQ(j["ready"], true);
    EXPECT_DOUBLE_EQ(j["ready_s"].get<double>(), 4.3);
    EXPECT_EQ(j["state"], "PARKING");
    EXPECT_EQ(j["mode"], "HOLD");
    EXPECT_DOUBLE_EQ(j["position"]["lat"].get<double>(), 41.3);
    EXPECT_DOUBLE_EQ(j["position"]["lon"].get<double>(), 2.1);
    EXPECT_EQ(j["mission_current"], 3);
    EXPECT_EQ(j["reboots"], 1);
    EXPECT_EQ(j["link_losses"], 4);
    EXPECT_EQ(j["link_verdicts_deferred"], 5);
    EXPECT_EQ(j["syncs"], 2);
    EXPECT_EQ(j["reconnects"], 2);
    const auto down = autopilot_status_json(autopilot::AutopilotStatus{});
    EXPECT_EQ(down["link"], "down");
    EXPECT_TRUE(down["ready_s"].is_null());
    EXPECT_TRUE(down["position"].is_null());
    EXPECT_FALSE(down.contains("tlog")) << "no recorder, no section";
}

TEST(AutopilotStatusJson, TlogWriteErrorsAreReported) {
    autopilot::AutopilotStatus s;
    s.tlog_enabled = true;
    EXPECT_TRUE(autopilot_status_json(s)["tlog"]["error"].is_null());
    s.tlog_write_errors = 2;
    s.tlog_dropped_frames = 40;
    s.tlog_error = "write /var/log/airseg/autopilot.tlog: No space left on device";
    const auto j = autopilot_status_json(s)["tlog"];
    EXPECT_EQ(j["write_errors"], 2);
    EXPECT_EQ(j["dropped_frames"], 40);
    EXPECT_EQ(j["error"], "write /var/log/airseg/autopilot.tlog: No space left on device");
}

TEST(AutopilotCommands, ResultsMapToCommandStatuses) {
    autopilot::RequestDone done;
    done.result = autopilot::RequestResult::Ok;
    auto ok = command_result(done, {{"state", "PARKING"}});
    EXPECT_EQ(ok.status, CommandStatus::Ok);
    EXPECT_EQ(ok.result["state"], "PARKING");
    done.result = autopilot::RequestResult::Refused;
    done.detail = "not allowed from MANUAL";
    auto refused = command_result(done, {});
    EXPECT_EQ(refused.status, CommandStatus::Refused);
    EXPECT_NE(refused.error.find("not allowed from MANUAL"), std::string::npos);
    done.result = autopilot::RequestResult::Timeout;
    EXPECT_EQ(command_result(done, {}).status, CommandStatus::Failed);
    done.result = autopilot::RequestResult::Invalid;
    EXPECT_EQ(command_result(done, {}).status, CommandStatus::BadRequest);
}

TEST(Cli, BadArgumentsExitTwoWithUsage) {
    const char* argv[] = {"airsegd", "--frobnicate"};
    auto r = parse_cli(2, argv);
    EXPECT_EQ(r.action, CliResult::Action::Exit);
    EXPECT_EQ(r.exit_code, 2);
    EXPECT_NE(r.output.find("unrecognised option '--frobnicate'"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("see airsegd --help"), std::string::npos) << r.output;

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
