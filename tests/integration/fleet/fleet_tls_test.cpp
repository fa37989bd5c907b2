// The fleet over TLS: mosquitto with a TLS listener that requires client certificates (the certificate's CN
// is the user the ACL sees), and a second one whose own certificate has expired; every certificate made here,
// at run time, with the openssl command: a CA, the broker's (subjectAltName IP:127.0.0.1, DNS:localhost), the
// hub's and the operator's, a second CA that signed none of them, and expired ones. A vehicle's hub and
// airsegctl reach each other through the broker over TLS; a broker certificate from another CA, an expired
// broker certificate, an expired client certificate and TLS files that cannot work are refused, each with its
// message. docs/fleet.md, "TLS with client certificates".
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tests/support/ground_chain.hpp"
#include "tests/support/json_lines.hpp"
#include "tests/support/ports.hpp"
#include "tests/support/process.hpp"

namespace airseg::test {
namespace {

using Json = nlohmann::json;
constexpr auto kGenerous = 60s;

std::size_t count_of(const std::string& text, const std::string& needle) {
    std::size_t n = 0;
    for (auto at = text.find(needle); at != std::string::npos; at = text.find(needle, at + needle.size())) {
        ++n;
    }
    return n;
}

class FleetTls : public ::testing::Test {
  protected:
    void SetUp() override {
        const auto found =
            run({"/bin/sh", "-c",
                 "PATH=$PATH:/usr/sbin:/usr/local/sbin command -v mosquitto && command -v openssl"});
        ASSERT_EQ(found.exit_code, 0)
            << "mosquitto or openssl is not installed: sudo apt-get install mosquitto openssl";
        std::istringstream paths(found.out);
        std::getline(paths, mosquitto);
        std::getline(paths, openssl);
        port = reserve_loopback_port();
        expired_port = reserve_loopback_port();
        elsewhere_port = reserve_loopback_port();
        ASSERT_NO_FATAL_FAILURE(make_certificates());
        ASSERT_NO_FATAL_FAILURE(start_broker());
    }

    void openssl_run(std::vector<std::string> args) {
        args.insert(args.begin(), openssl);
        const auto r = run(args);
        ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
    }
    void make_key(const std::string& name) {
        openssl_run({"genpkey", "-algorithm", "EC", "-pkeyopt", "ec_paramgen_curve:P-256", "-out",
                     file(name + ".key")});
    }
    void make_ca(const std::string& name, const std::string& cn) {
        ASSERT_NO_FATAL_FAILURE(make_key(name));
        openssl_run({"req", "-x509", "-key", file(name + ".key"), "-out", file(name + ".crt"), "-days",
                     "3650", "-subj", "/CN=" + cn});
    }
    /// A certificate for `cn` signed by the test CA, valid from `start` to `end` (openssl ca: the one way to
    /// make one already expired).
    void make_signed(const std::string& name, const std::string& cn, const std::string& extensions,
                     const std::string& start, const std::string& end) {
        ASSERT_NO_FATAL_FAILURE(make_key(name));
        openssl_run(
            {"req", "-new", "-key", file(name + ".key"), "-out", file(name + ".csr"), "-subj", "/CN=" + cn});
        write_file(file(name + ".ext"), extensions + "\n");
        openssl_run({"ca", "-batch", "-notext", "-config", file("ca.cnf"), "-cert", file("ca.crt"),
                     "-keyfile", file("ca.key"), "-in", file(name + ".csr"), "-out", file(name + ".crt"),
                     "-extfile", file(name + ".ext"), "-startdate", start, "-enddate", end});
    }
    void make_certificates() {
        ASSERT_NO_FATAL_FAILURE(make_ca("ca", "airseg-test-ca"));
        ASSERT_NO_FATAL_FAILURE(make_ca("other-ca", "unrelated-ca"));
        write_file(file("index.txt"), "");
        write_file(file("serial"), "01\n");
        write_file(file("ca.cnf"), "[ca]\ndefault_ca = test\n[test]\ndatabase = " + file("index.txt") +
                                       "\nnew_certs_dir = " + dir.path() + "\nserial = " + file("serial") +
                                       "\ndefault_md = sha256\npolicy = any\nunique_subject = no\n"
                                       "[any]\ncommonName = supplied\n");
        const std::string server = "subjectAltName=IP:127.0.0.1,DNS:localhost";
        const std::string client = "extendedKeyUsage=clientAuth";
        constexpr auto kLongAgo = "20200101000000Z";
        constexpr auto kShortlyAfter = "20200102000000Z";
        constexpr auto kFarAhead = "20991231000000Z";
        ASSERT_NO_FATAL_FAILURE(make_signed("broker", "localhost", server, kLongAgo, kFarAhead));
        ASSERT_NO_FATAL_FAILURE(make_signed("expired-broker", "localhost", server, kLongAgo, kShortlyAfter));
        ASSERT_NO_FATAL_FAILURE(make_signed("elsewhere-broker", "elsewhere",
                                            "subjectAltName=DNS:elsewhere.lan", kLongAgo, kFarAhead));
        ASSERT_NO_FATAL_FAILURE(make_signed("hub1", "hub1", client, kLongAgo, kFarAhead));
        ASSERT_NO_FATAL_FAILURE(make_signed("operator", "operator", client, kLongAgo, kFarAhead));
        ASSERT_NO_FATAL_FAILURE(make_signed("expired-operator", "operator", client, kLongAgo, kShortlyAfter));
    }

    void start_broker() {
        write_file(file("acl"),
                   "user hub1\ntopic write airseg/rover1/#\ntopic read airseg/rover1/cmd\n\n"
                   "user operator\ntopic write airseg/+/cmd\ntopic read airseg/#\n");
        write_file(
            file("mosquitto.conf"),
            "allow_anonymous false\nacl_file " + file("acl") + "\n" +
                // The fleet's listener: certificates on both sides.
                "listener " + std::to_string(port) + " 127.0.0.1\ncafile " + file("ca.crt") + "\ncertfile " +
                file("broker.crt") + "\nkeyfile " + file("broker.key") +
                "\nrequire_certificate true\nuse_identity_as_username true\n" +
                // A broker whose certificate has expired.
                "listener " + std::to_string(expired_port) + " 127.0.0.1\ncafile " + file("ca.crt") +
                "\ncertfile " + file("expired-broker.crt") + "\nkeyfile " + file("expired-broker.key") +
                "\nrequire_certificate true\nuse_identity_as_username true\n" +
                // A broker whose certificate names another host.
                "listener " + std::to_string(elsewhere_port) + " 127.0.0.1\ncafile " + file("ca.crt") +
                "\ncertfile " + file("elsewhere-broker.crt") + "\nkeyfile " + file("elsewhere-broker.key") +
                "\nrequire_certificate true\nuse_identity_as_username true\n" +
                "log_dest stderr\nlog_type all\n" + (::geteuid() == 0 ? "user root\n" : ""));
        broker =
            std::make_unique<Subprocess>(std::vector<std::string>{mosquitto, "-c", file("mosquitto.conf")},
                                         std::map<std::string, std::string>{}, dir.path());
        ASSERT_TRUE(wait_until([&] { return broker->err().find("running") != std::string::npos; }, kGenerous))
            << broker->err();
    }

    std::string file(const std::string& name) const { return dir.file(name); }
    std::string at(int p) const { return "127.0.0.1:" + std::to_string(p); }

    /// The TLS options of `who` (hub1, operator, expired-operator), trusting `ca`.
    std::vector<std::string> tls(const std::string& who, const std::string& ca = "ca") const {
        return {"--mqtt-ca",        file(ca + ".crt"), "--mqtt-cert",
                file(who + ".crt"), "--mqtt-key",      file(who + ".key")};
    }

    RunResult airsegctl(int to, std::vector<std::string> tls_args, std::vector<std::string> args,
                        long timeout_ms = 30'000) const {
        std::vector<std::string> argv{
            binary("client/airsegctl"), "--mqtt", at(to), "--vehicle", "rover1", "--json", "--timeout",
            std::to_string(timeout_ms)};
        argv.insert(argv.end(), tls_args.begin(), tls_args.end());
        argv.insert(argv.end(), args.begin(), args.end());
        return run(argv, {}, 90s);
    }

    /// A hub without a vehicle (its radio points at nothing) for its fleet bridge alone.
    std::vector<std::string> bare_hub(int to, std::vector<std::string> tls_args) {
        write_file(file("control.key"), std::string(64, 'c') + "\n");
        ::chmod(file("control.key").c_str(), 0600);
        std::vector<std::string> argv{binary("ground/airseg-ground"),
                                      "--udp",
                                      at(reserve_loopback_port()),
                                      "--key",
                                      file("control.key"),
                                      "--socket",
                                      file("bare.sock"),
                                      "--map",
                                      "off",
                                      "--mavlink-udp",
                                      "off",
                                      "--mavlink-udp-listen",
                                      "off",
                                      "--mavlink-tcp",
                                      "off",
                                      "--mqtt",
                                      at(to),
                                      "--vehicle",
                                      "rover1"};
        argv.insert(argv.end(), tls_args.begin(), tls_args.end());
        return argv;
    }

    TempDir dir;
    std::string mosquitto, openssl;
    int port = 0;
    int expired_port = 0;
    int elsewhere_port = 0;
    std::unique_ptr<Subprocess> broker;
};

TEST_F(FleetTls, AVehicleAndAnOperatorMeetOverTlsWithClientCertificates) {
    GroundChain rover1(file("rover1"), [&] {
        std::vector<std::string> args{
            "--map",     "off",           "--mavlink-udp", "off",    "--mavlink-udp-listen",
            "off",       "--mavlink-tcp", "off",           "--mqtt", at(port),
            "--vehicle", "rover1"};
        const auto t = tls("hub1");
        args.insert(args.end(), t.begin(), t.end());
        return args;
    }());
    ASSERT_EQ(rover1.start(), "");
    ASSERT_TRUE(wait_until([&] { return rover1.hub->err().find("fleet: connected") != std::string::npos; },
                           kGenerous, 100ms))
        << rover1.hub->err() << "\nbroker:\n"
        << broker->err();

    // A command through the broker, answered by the vehicle through its hub.
    const auto status = airsegctl(port, tls("operator"), {"status"});
    ASSERT_EQ(status.exit_code, 0) << status.out << status.err << "\nhub:\n" << rover1.hub->err();
    EXPECT_TRUE(Json::parse(status.out, nullptr, false).value("autopilot", Json()).is_object()) << status.out;

    // The vehicle's telemetry, published by the hub's bridge, seen live.
    const auto view = airsegctl(port, tls("operator"), {"watch", "--duration", "3000"});
    ASSERT_EQ(view.exit_code, 0) << view.err;
    const auto lines = json_lines(view.out);
    ASSERT_FALSE(lines.empty()) << view.err;
    EXPECT_GE(lines.back()["samples"].get<int>(), 2) << lines.back().dump();
    EXPECT_NEAR(lines.back()["vehicle"].value("lat", 0.0), GroundChain::kHomeLat, 0.01)
        << lines.back().dump();
    EXPECT_EQ(lines.back()["ground_link"]["link"], "up") << lines.back().dump();
    // The broker saw the certificates' names as the users.
    EXPECT_NE(broker->err().find("as airseg-ground-rover1"), std::string::npos) << broker->err();
    EXPECT_NE(broker->err().find("u'hub1'"), std::string::npos) << broker->err();
}

TEST_F(FleetTls, ABrokerCertificateFromAnotherCaIsRefused) {
    const auto refused = airsegctl(port, tls("operator", "other-ca"), {"status"});
    EXPECT_EQ(refused.exit_code, 3);
    EXPECT_EQ(refused.err,
              "airsegctl: MQTT broker " + at(port) +
                  ": TLS handshake failed: the broker's certificate (CN=localhost) is not signed by "
                  "the CA of --mqtt-ca " +
                  file("other-ca.crt") +
                  " (self-signed certificate in certificate chain; is it the broker's CA?)\n");

    // The hub says it once, and keeps trying as for a broker that is down: the broker logs every attempt
    // (airsegctl's and three of the hub's) with the alert the client sent.
    Subprocess hub(bare_hub(port, tls("hub1", "other-ca")), {}, dir.path());
    const auto line =
        "fleet: MQTT broker " + at(port) +
        ": TLS handshake failed: the broker's certificate (CN=localhost) is not signed by the CA "
        "of --mqtt-ca " +
        file("other-ca.crt");
    ASSERT_TRUE(
        wait_until([&] { return count_of(broker->err(), "alert unknown ca") >= 4; }, kGenerous, 100ms))
        << "the hub tries again: " << broker->err() << "\nhub:\n"
        << hub.err();
    EXPECT_EQ(count_of(hub.err(), line), 1u) << hub.err();
    EXPECT_EQ(hub.err().find("fleet: connected"), std::string::npos) << hub.err();
}

TEST_F(FleetTls, AnExpiredBrokerCertificateIsRefused) {
    const auto refused = airsegctl(expired_port, tls("operator"), {"status"});
    EXPECT_EQ(refused.exit_code, 3);
    EXPECT_EQ(refused.err,
              "airsegctl: MQTT broker " + at(expired_port) +
                  ": TLS handshake failed: the broker's certificate (CN=localhost) has expired (valid "
                  "until Jan  2 00:00:00 2020 GMT)\n");
}

TEST_F(FleetTls, ABrokerCertificateForAnotherHostIsRefused) {
    const auto refused = airsegctl(elsewhere_port, tls("operator"), {"status"});
    EXPECT_EQ(refused.exit_code, 3);
    EXPECT_EQ(refused.err, "airsegctl: MQTT broker " + at(elsewhere_port) +
                               ": TLS handshake failed: the broker's certificate (CN=elsewhere) is not for "
                               "127.0.0.1 (neither its CN nor its subjectAltName names it)\n");
    // The same broker by a name its certificate has not either: localhost.
    auto argv = std::vector<std::string>{binary("client/airsegctl"),
                                         "--mqtt",
                                         "localhost:" + std::to_string(elsewhere_port),
                                         "--vehicle",
                                         "rover1",
                                         "--timeout",
                                         "30000"};
    for (const auto& a : tls("operator")) {
        argv.push_back(a);
    }
    argv.push_back("status");
    const auto by_name = run(argv, {}, 90s);
    EXPECT_EQ(by_name.exit_code, 3);
    EXPECT_NE(by_name.err.find("the broker's certificate (CN=elsewhere) is not for localhost"),
              std::string::npos)
        << by_name.err;
}

TEST_F(FleetTls, AnExpiredClientCertificateIsRefusedByTheBroker) {
    const auto refused = airsegctl(port, tls("expired-operator"), {"status"});
    EXPECT_EQ(refused.exit_code, 3);
    EXPECT_EQ(refused.err,
              "airsegctl: MQTT broker " + at(port) +
                  ": TLS handshake failed: the broker refused the client certificate (--mqtt-cert): "
                  "it has expired (sslv3 alert certificate expired)\n");
    EXPECT_NE(broker->err().find("certificate verify failed"), std::string::npos) << broker->err();

    // Without any client certificate at all.
    const auto anonymous = airsegctl(port, {"--mqtt-ca", file("ca.crt")}, {"status"});
    EXPECT_EQ(anonymous.exit_code, 3);
    EXPECT_EQ(anonymous.err,
              "airsegctl: MQTT broker " + at(port) +
                  ": TLS handshake failed: the broker requires a client certificate (--mqtt-cert "
                  "and --mqtt-key) (tlsv13 alert certificate required)\n");
}

TEST_F(FleetTls, TlsFilesThatCannotWorkAreNamedBeforeConnecting) {
    auto t = tls("operator");
    t[1] = file("missing.crt");
    const auto missing = airsegctl(port, t, {"status"});
    EXPECT_EQ(missing.exit_code, 3);
    EXPECT_EQ(missing.err, "airsegctl: --mqtt-ca " + file("missing.crt") +
                               ": cannot open it: No such file or directory\n");

    t = tls("operator");
    t[1] = file("operator.key");
    const auto not_a_certificate = airsegctl(port, t, {"status"});
    EXPECT_EQ(not_a_certificate.err,
              "airsegctl: --mqtt-ca " + file("operator.key") + ": no PEM certificate in it\n");

    t = tls("operator");
    t[5] = file("hub1.key");
    const auto foreign_key = airsegctl(port, t, {"status"});
    EXPECT_EQ(foreign_key.exit_code, 3);
    EXPECT_EQ(foreign_key.err, "airsegctl: --mqtt-key " + file("hub1.key") +
                                   " is not the key of --mqtt-cert " + file("operator.crt") +
                                   " (key values mismatch)\n");

    const auto usage =
        airsegctl(port, {"--mqtt-ca", file("ca.crt"), "--mqtt-cert", file("operator.crt")}, {"status"});
    EXPECT_EQ(usage.exit_code, 2) << usage.err;
    EXPECT_NE(usage.err.find("--mqtt-cert and --mqtt-key go together"), std::string::npos) << usage.err;

    // The hub does not start with a file it cannot use.
    t = tls("hub1");
    t[3] = file("missing.crt");
    const auto hub = run(bare_hub(port, t), {}, 30s);
    EXPECT_EQ(hub.exit_code, 1);
    EXPECT_NE(hub.err.find("airseg-ground: --mqtt-cert " + file("missing.crt") +
                           ": cannot open it: No such file or directory"),
              std::string::npos)
        << hub.err;
}

}  // namespace
}  // namespace airseg::test
