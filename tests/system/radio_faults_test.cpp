// System fault injection on the ground radio: real airseg-apmsim ⇄ airsegd ⇄ airseg-linksim (57600 baud) ⇄
// airsegctl on pseudo-terminals. Each scenario sends uniquely identifiable commands (`rates vehicle=V`, V
// different for each) and ends with: each answered once with its own answer, the daemon's groundlink
// `commands` counter grown by exactly as many, the daemon alive, and the fault visible in status.
#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <random>

#include "tests/system/system_checks.hpp"

namespace airseg::test::sys {
namespace {

TEST(SystemRadio, FrameLossSweepEveryCommandAnsweredOnce) {
    SystemBench bench;
    int serial = 0;
    for (const double loss : {0.0, 0.1, 0.2, 0.3}) {
        ASSERT_EQ(bench.link().ask("frame-loss " + rate_text(loss)).value_or("").rfind("ok", 0), 0u);
        const auto before = bench.status();
        const auto started = std::chrono::steady_clock::now();
        CommandTally tally;
        for (int i = 0; i < 3; ++i) {
            send_unique(bench, serial++, tally, 60'000);
        }
        const double took = seconds_since(started);
        const auto after = bench.status();
        const auto stats = bench.link().json("stats");
        std::cout << "[ figures ] frame loss " << loss << ": " << tally.answered << "/" << tally.sent
                  << " answered in " << took << " s; daemon Safe retransmissions "
                  << counter(after, "/groundlink/tx/safe/retransmissions") -
                         counter(before, "/groundlink/tx/safe/retransmissions")
                  << "; radio packets lost (total) ab " << counter(stats, "/ab/packets_lost") << " ba "
                  << counter(stats, "/ba/packets_lost") << "\n";
        expect_each_answered_once(tally, counter(before, "/groundlink/commands"),
                                  counter(after, "/groundlink/commands"));
    }
    // The fault is visible: the radio lost packets, and the daemon resent what the ground did not get.
    const auto doc = bench.status();
    const auto stats = bench.link().json("stats");
    EXPECT_GT(counter(stats, "/ab/packets_lost") + counter(stats, "/ba/packets_lost"), 0u) << stats.dump();
    EXPECT_GT(counter(doc, "/groundlink/tx/safe/retransmissions"), 0u) << doc["groundlink"].dump();
    expect_daemon_alive(bench);
}

TEST(SystemRadio, ByteCorruptionIsCaughtByTheCrcAndEveryCommandAnsweredOnce) {
    BenchOptions o;
    o.link_args = {"--corrupt", "0.002"};
    SystemBench bench(o);
    const auto before = bench.status();
    CommandTally tally;
    for (int i = 0; i < 6; ++i) {
        send_unique(bench, i, tally, 60'000);
    }
    const auto after = bench.status();
    expect_each_answered_once(tally, counter(before, "/groundlink/commands"),
                              counter(after, "/groundlink/commands"));
    const auto stats = bench.link().json("stats");
    const auto& g = after["groundlink"];
    std::cout << "[ figures ] corruption 0.002/byte: " << tally.answered << "/" << tally.sent
              << " answered; bytes corrupted ab " << counter(stats, "/ab/bytes_corrupted") << " ba "
              << counter(stats, "/ba/bytes_corrupted") << "; daemon crc_errors " << g.value("crc_errors", 0)
              << " framing_errors " << g.value("framing_errors", 0) << " Safe retransmissions "
              << counter(after, "/groundlink/tx/safe/retransmissions") << "\n";
    EXPECT_GT(counter(stats, "/ba/bytes_corrupted"), 0u) << stats.dump();
    EXPECT_GT(counter(after, "/groundlink/crc_errors") + counter(after, "/groundlink/framing_errors"), 0u)
        << "the damaged frames the daemon received are counted: " << g.dump();
    expect_daemon_alive(bench);
}

// Weak signal on a radio without error correction: 2 % of the bytes lost independently, each way. Every
// `airsegctl status` (a new session each: handshake, command, compressed answer) is answered, the frames are
// protected by forward error correction, and the median answer comes within 3 s (docs/ground-link.md,
// "Forward error correction").
TEST(SystemRadio, TwoPercentByteLossStatusAnsweredInSeconds) {
    BenchOptions o;
    o.link_args = {"--loss", "0.02"};
    SystemBench bench(o);
    ASSERT_TRUE(bench.wait_ready()) << bench.logs();
    std::vector<double> took;
    int answered = 0;
    for (int i = 0; i < 20; ++i) {
        const auto t = std::chrono::steady_clock::now();
        const auto r = bench.ctl({"status"}, 60'000);
        took.push_back(seconds_since(t));
        const auto doc = Json::parse(r.out, nullptr, false);
        if (r.exit_code == 0 && doc.is_object() && doc.contains("groundlink")) {
            ++answered;
        } else {
            ADD_FAILURE() << "status " << i << " exit " << r.exit_code << ": " << r.err;
        }
    }
    std::vector<double> sorted = took;
    std::sort(sorted.begin(), sorted.end());
    const double median = (sorted[9] + sorted[10]) / 2;
    const auto doc = bench.status();
    const auto& g = doc["groundlink"];
    const auto stats = bench.link().json("stats");
    std::cout << "[ figures ] 2 % byte loss: " << answered << "/20 status answered; median " << median
              << " s, fastest " << sorted.front() << " s, slowest " << sorted.back()
              << " s; daemon byte error rate " << g.value("byte_error_rate", Json()).dump() << ", fec "
              << g.value("fec", Json()).dump() << "; radio bytes lost ab " << counter(stats, "/ab/bytes_lost")
              << " ba " << counter(stats, "/ba/bytes_lost") << "\n";
    EXPECT_EQ(answered, 20);
    EXPECT_GT(counter(stats, "/ab/bytes_lost") + counter(stats, "/ba/bytes_lost"), 0u) << stats.dump();
    EXPECT_TRUE(g["fec"].value("active", false)) << g.dump();
    EXPECT_GT(counter(doc, "/groundlink/fec/frames_decoded"), 0u) << g.dump();
    EXPECT_NEAR(g.value("byte_error_rate", 0.0), 0.02, 0.01) << g.dump();
#ifndef AIRSEG_SLOWED_BUILD
    EXPECT_LE(median, 3.0);
#endif
    expect_daemon_alive(bench);
}

TEST(SystemRadio, ASixtySecondOutageDelaysButLosesNoCommand) {
    SystemBench bench;
    const auto before = bench.status();
    CommandTally tally;
    send_unique(bench, 0, tally);
    ASSERT_EQ(tally.answered, 1) << tally.problems.front() << bench.logs();
    ASSERT_TRUE(wait_until([&] { return section(bench.status(), "groundlink").value("link", "") == "up"; },
                           kGenerous, kPoll));

    ASSERT_EQ(bench.link().ask("outage 60").value_or("").rfind("ok", 0), 0u);
    const auto outage_start = std::chrono::steady_clock::now();
    // A command queued into the outage, from its own client; the link goes down meanwhile.
    ++tally.sent;
    Subprocess during({binary("client/airsegctl"), "--link", bench.ground_link(), "--timeout", "150000",
                       "--json", "rates", "vehicle=" + rate_text(unique_rate(1))},
                      {}, bench.dir().path());
    EXPECT_TRUE(wait_until([&] { return section(bench.status(), "groundlink").value("link", "") == "down"; },
                           kGenerous, kPoll))
        << "the outage is visible in status";
    const double down_after = seconds_since(outage_start);
    ASSERT_EQ(during.wait_exit(std::chrono::seconds(160)), 0) << during.err() << bench.logs();
    const double answered_after = seconds_since(outage_start);
    const auto j = Json::parse(during.out(), nullptr, false);
    ASSERT_TRUE(j.is_object()) << during.out();
    EXPECT_DOUBLE_EQ(j["requested_hz"]["vehicle"].get<double>(), unique_rate(1));
    ++tally.answered;
    EXPECT_GT(answered_after, 55.0) << "the answer cannot have crossed the outage";
    EXPECT_LT(answered_after, 80.0) << "the link recovers within seconds of the outage's end";

    // And after it: at once.
    const auto t = std::chrono::steady_clock::now();
    send_unique(bench, 2, tally);
    const double after_s = seconds_since(t);
    const auto after = bench.status();
    std::cout << "[ figures ] 60 s outage: link down " << down_after << " s in; queued command answered "
              << answered_after << " s after the outage began (" << answered_after - 60
              << " s after its end); next command " << after_s << " s; Safe retransmissions "
              << counter(after, "/groundlink/tx/safe/retransmissions") << "\n";
    expect_each_answered_once(tally, counter(before, "/groundlink/commands"),
                              counter(after, "/groundlink/commands"));
    EXPECT_EQ(after["groundlink"]["link"], "up");
    expect_daemon_alive(bench);
}

TEST(SystemRadio, OnePairOfASplitLinkDeadAndBack) {
    BenchOptions o;
    o.radios = 2;
    SystemBench bench(o);
    const auto before = bench.status();
    CommandTally tally;
    send_unique(bench, 0, tally);
    send_unique(bench, 1, tally);
    ASSERT_EQ(tally.answered, 2) << bench.logs();

    // Pair 1 (ground → air) dies: both of its radios off.
    ASSERT_EQ(bench.link(1).ask("down a").value_or("").rfind("ok", 0), 0u);
    ASSERT_EQ(bench.link(1).ask("down b").value_or("").rfind("ok", 0), 0u);
    const auto died = std::chrono::steady_clock::now();
    send_unique(bench, 2, tally, 60'000);
    send_unique(bench, 3, tally, 60'000);
    const double during_s = seconds_since(died);
    Json paths;
    EXPECT_TRUE(wait_until(
        [&] {
            paths = section(bench.status(), "groundlink").value("paths", Json::array());
            return paths.size() == 2 && !paths[1].value("alive", true);
        },
        kGenerous, kPoll))
        << "the dead pair is visible in status: " << paths.dump();

    ASSERT_EQ(bench.link(1).ask("up a").value_or("").rfind("ok", 0), 0u);
    ASSERT_EQ(bench.link(1).ask("up b").value_or("").rfind("ok", 0), 0u);
    const auto back = std::chrono::steady_clock::now();
    send_unique(bench, 4, tally, 60'000);
    EXPECT_TRUE(wait_until(
        [&] {
            send_unique(bench, 5 + tally.sent, tally, 60'000);  // traffic makes the path seen again
            paths = section(bench.status(), "groundlink").value("paths", Json::array());
            return paths.size() == 2 && paths[1].value("alive", false);
        },
        kGenerous, kPoll))
        << "the pair is alive again: " << paths.dump();
    const double recovered_s = seconds_since(back);
    const auto after = bench.status();
    std::cout << "[ figures ] split link, pair 1 dead: 2 commands answered in " << during_s
              << " s over the other pair; pair seen alive " << recovered_s << " s after it came back; "
              << tally.answered << "/" << tally.sent << " answered\n";
    expect_each_answered_once(tally, counter(before, "/groundlink/commands"),
                              counter(after, "/groundlink/commands"));
    expect_daemon_alive(bench);
}

/// Opens a pty end as a serial program does (raw).
int open_raw(const std::string& path) {
    const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (fd >= 0) {
        termios t{};
        ::tcgetattr(fd, &t);
        ::cfmakeraw(&t);
        ::tcsetattr(fd, TCSANOW, &t);
    }
    return fd;
}

TEST(SystemRadio, GarbageAndOversizedMessagesFromTheGroundAreRejectedAndCounted) {
    BenchOptions o;
    o.key = true;
    SystemBench bench(o);
    CommandTally tally;
    send_unique(bench, 0, tally);
    ASSERT_EQ(tally.answered, 1) << bench.logs();
    const auto before = bench.status();

    // Raw garbage into the ground radio: random bytes with frame delimiters among them, so that the daemon
    // sees many would-be frames.
    {
        const int fd = open_raw(bench.ground_port());
        ASSERT_GE(fd, 0);
        std::mt19937 rng(5);
        std::string junk;
        for (int i = 0; i < 6000; ++i) {
            junk.push_back(i % 97 == 0 ? '\0' : static_cast<char>(rng() & 0xff));
        }
        std::size_t done = 0;
        while (done < junk.size()) {
            const auto n = ::write(fd, junk.data() + done, std::min<std::size_t>(512, junk.size() - done));
            ASSERT_GT(n, 0);
            done += static_cast<std::size_t>(n);
        }
        // Until the radio has carried it all (6000 bytes at 5760 B/s).
        Json g;
        EXPECT_TRUE(wait_until(
            [&] {
                g = section(bench.status(), "groundlink");
                return counter(g, "/framing_errors") + counter(g, "/crc_errors") +
                           counter(g, "/mac_failures") >
                       counter(before["groundlink"], "/framing_errors") +
                           counter(before["groundlink"], "/crc_errors") +
                           counter(before["groundlink"], "/mac_failures") + 20;
            },
            kGenerous, kPoll))
            << g.dump();
        ::close(fd);
    }
    // A command far larger than a message may be (64 KiB): refused before it goes on the air.
    const auto mid = bench.status();
    // Random letters: commands are compressed, so a long run of one letter would be small on the air.
    std::string pad(120 * 1024, 'x');  // below the 128 KiB a single argument may have
    const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
    std::mt19937 letters(5);
    for (auto& c : pad) {
        c = alphabet[letters() % alphabet.size()];
    }
    const std::string big = R"({"cmd":"rates.set","pad":")" + pad + R"("})";
    const auto sent_big = std::chrono::steady_clock::now();
    auto oversized = bench.ctl({"request", big}, 20'000);
    const double big_s = seconds_since(sent_big);
    EXPECT_EQ(oversized.exit_code, 1) << oversized.out << oversized.err;
    const auto big_why = Json::parse(oversized.out, nullptr, false);
    EXPECT_EQ(big_why.value("status", ""), "bad_request") << oversized.out;
    EXPECT_NE(big_why.value("error", "").find("not sent"), std::string::npos) << oversized.out;
    EXPECT_LT(big_s, 10.0) << "refused at once, not after the timeout";
    // Commands the vehicle cannot make sense of: answered with an error, counted.
    auto unknown = bench.ctl({"request", R"({"cmd":"warp","factor":9})"});
    EXPECT_EQ(unknown.exit_code, 1) << unknown.out << unknown.err;
    EXPECT_EQ(Json::parse(unknown.out, nullptr, false).value("status", ""), "unknown_command") << unknown.out;
    auto not_object = bench.ctl({"request", "[1,2,3]"});
    EXPECT_NE(not_object.exit_code, 0) << not_object.out << not_object.err;
    EXPECT_FALSE(not_object.out.empty() && not_object.err.empty());

    // A normal command still works.
    send_unique(bench, 1, tally);
    const auto after = bench.status();
    const auto& g = after["groundlink"];
    const auto received = counter(after, "/groundlink/commands") - counter(mid, "/groundlink/commands");
    std::cout << "[ figures ] garbage: 6000 random bytes -> framing_errors "
              << counter(g, "/framing_errors") - counter(before["groundlink"], "/framing_errors")
              << ", crc_errors " << counter(g, "/crc_errors") - counter(before["groundlink"], "/crc_errors")
              << ", mac_failures "
              << counter(g, "/mac_failures") - counter(before["groundlink"], "/mac_failures")
              << ", bad_messages " << counter(g, "/bad_messages") << "; oversized (120 KiB) command: exit "
              << oversized.exit_code << " in " << big_s << " s " << oversized.out.substr(0, 200)
              << "; unknown: " << unknown.out << "; not an object: exit " << not_object.exit_code << " "
              << not_object.out << not_object.err << "; daemon received " << received
              << " commands after the garbage\n";
    // The oversized one never reached the vehicle; the unknown one and the normal one did, once each (the
    // array reaches it only if the client sends it).
    EXPECT_GE(received, 2u);
    EXPECT_LE(received, 3u);
    EXPECT_EQ(tally.answered, tally.sent) << tally.problems.back();
    EXPECT_EQ(tally.wrong_answer, 0);
    expect_daemon_alive(bench);
}

TEST(SystemRadio, AFloodOfCommandsIsAnsweredOrCleanlyRefusedNeverDuplicated) {
    SystemBench bench;
    const auto before = bench.status();
    // Rapid calls over the radio, one after the other with no pause.
    CommandTally tally;
    const auto started = std::chrono::steady_clock::now();
    for (int i = 0; i < 20; ++i) {
        send_unique(bench, i, tally, 60'000);
    }
    const double rapid_s = seconds_since(started);
    const auto mid = bench.status();
    expect_each_answered_once(tally, counter(before, "/groundlink/commands"),
                              counter(mid, "/groundlink/commands"));
    for (int i = 0; i < 20; ++i) {
        EXPECT_EQ(times_requested(bench, unique_rate(i)), 1) << "request #" << i << " in the daemon's log";
    }

    // Then three ground stations at once on the same radio, each with its own values, and 40 local clients at
    // once (the socket serves 16 connections): each radio call is answered with its own answer or ends with
    // an error (a ground station taking over ends another's session); never a wrong or a doubled answer.
    std::vector<std::unique_ptr<Subprocess>> radio, local;
    for (int i = 0; i < 3; ++i) {
        radio.push_back(std::make_unique<Subprocess>(
            std::vector<std::string>{binary("client/airsegctl"), "--link", bench.ground_link(), "--timeout",
                                     "20000", "--json", "rates",
                                     "vehicle=" + rate_text(unique_rate(100 + i))},
            std::map<std::string, std::string>{}, bench.dir().path()));
    }
    for (int i = 0; i < 40; ++i) {
        local.push_back(
            std::make_unique<Subprocess>(std::vector<std::string>{binary("client/airsegctl"), "--local",
                                                                  "--socket", bench.dir().file("status.sock"),
                                                                  "--json", "--timeout", "30000", "status"},
                                         std::map<std::string, std::string>{}, bench.dir().path()));
    }
    int radio_answered = 0, radio_failed = 0, local_answered = 0, local_refused = 0;
    for (std::size_t i = 0; i < radio.size(); ++i) {
        const auto code = radio[i]->wait_exit(std::chrono::seconds(90));
        ASSERT_TRUE(code.has_value());
        const auto j = Json::parse(radio[i]->out(), nullptr, false);
        if (*code == 0) {
            ASSERT_TRUE(j.is_object()) << radio[i]->out();
            EXPECT_DOUBLE_EQ(j["requested_hz"]["vehicle"].get<double>(),
                             unique_rate(100 + static_cast<int>(i)));
            ++radio_answered;
        } else {
            EXPECT_FALSE(radio[i]->err().empty() && radio[i]->out().empty()) << "a failure says why";
            ++radio_failed;
        }
    }
    for (auto& l : local) {
        const auto code = l->wait_exit(std::chrono::seconds(60));
        ASSERT_TRUE(code.has_value());
        if (*code == 0) {
            EXPECT_TRUE(Json::parse(l->out(), nullptr, false).contains("services"));
            ++local_answered;
        } else {
            EXPECT_FALSE(l->err().empty() && l->out().empty()) << "a refusal says why";
            ++local_refused;
        }
    }
    // The three stations wrote into one pty faster than the radio carries: their bytes wait in the emulator's
    // host backlog (up to 64 KiB, about 11 s at 57600 baud) after they exit, and a command among them may
    // still reach the vehicle. Count once the vehicle has heard nothing from the ground for its link timeout.
    const auto exited = bench.status();
    const auto quiet_from = std::chrono::steady_clock::now();
    ASSERT_TRUE(wait_until([&] { return section(bench.status(), "groundlink").value("link", "") == "down"; },
                           std::chrono::seconds(60)))
        << "the ground link goes down once the stations are gone";
    const auto end = bench.status();
    const auto received = counter(end, "/groundlink/commands") - counter(mid, "/groundlink/commands");
    std::cout << "[ figures ] flood: 20 sequential radio commands in " << rapid_s
              << " s, all answered once; 3 "
              << "concurrent radio clients: " << radio_answered << " answered, " << radio_failed
              << " failed cleanly, daemon received " << received
              << "; 40 concurrent local: " << local_answered << " answered, " << local_refused
              << " refused; peer_restarts " << counter(end, "/groundlink/peer_restarts") << "; link down "
              << seconds_since(quiet_from) << " s after the stations exited, "
              << counter(end, "/groundlink/commands") - counter(exited, "/groundlink/commands")
              << " command(s) arrived meanwhile\n";
    EXPECT_GE(received, static_cast<std::uint64_t>(radio_answered));
    EXPECT_LE(received, 3u) << "no command executed twice";
    for (int i = 0; i < 3; ++i) {
        EXPECT_LE(times_requested(bench, unique_rate(100 + i)), 1)
            << "station " << i << "'s request, executed twice";
    }
    // Several programs reading one serial line steal each other's bytes: that they fail (cleanly) is
    // expected; that the vehicle never executes more than was sent is the point.
    EXPECT_GE(local_answered, 16);

    // Afterwards a normal command works and is executed once: the daemon's log names each request, which
    // tells this one from any stray bytes of the stations above.
    CommandTally last;
    send_unique(bench, 50, last);
    EXPECT_EQ(last.answered, 1) << (last.problems.empty() ? "" : last.problems.front());
    ASSERT_TRUE(wait_until([&] { return section(bench.status(), "groundlink").value("link", "") == "down"; },
                           std::chrono::seconds(60)));
    EXPECT_EQ(times_requested(bench, unique_rate(50)), 1);
    expect_daemon_alive(bench);
    if (::testing::Test::HasFailure()) {
        std::ofstream("/tmp/flood_fail_" + std::to_string(getpid()) + ".log") << bench.logs();
    }
}

// At most once over the radio. An airsegctl that gets no answer says which request id to send its command
// again under; sent again under it, a command the vehicle never received is done then, and one whose answer
// was lost (the client gone as it travelled) is answered from the vehicle's record, not done twice.
TEST(SystemRadio, ACommandSentAgainUnderItsRequestIdIsDoneOnce) {
    BenchOptions o;
    o.speedup = 10;
    SystemBench bench(o);
    ASSERT_TRUE(bench.wait_ready()) << bench.logs();
    const auto route = bench.dir().file("route.yaml");
    const auto leg = bench.dir().file("leg2.yaml");
    write_file(route, line_plan("route", 6, 20));
    write_file(leg, line_plan("leg2", 3, 20, 30));
    const auto loaded = bench.ctl_local({"plan", "load", "--paused", route});
    ASSERT_EQ(loaded.exit_code, 0) << loaded.out << loaded.err << bench.logs();
    const auto elements = [&] {
        const auto r = bench.ctl_local({"plan", "show"});
        const auto j = Json::parse(r.out, nullptr, false);
        return j.is_object() && j.contains("elements") ? j["elements"].size() : std::size_t{0};
    };
    const std::size_t before = elements();
    ASSERT_GT(before, 0u);

    // 1. No answer (the radio silent both ways): airsegctl names the id to retry under.
    ASSERT_EQ(bench.link().ask("outage 6").value_or("").rfind("ok", 0), 0u);
    const auto cut = std::chrono::steady_clock::now();
    const auto unanswered = bench.ctl({"plan", "append", leg}, 2'000);
    EXPECT_EQ(unanswered.exit_code, 3) << unanswered.out << unanswered.err;
    const auto said = Json::parse(unanswered.out, nullptr, false);
    ASSERT_TRUE(said.is_object() && said.contains("request_id")) << unanswered.out << unanswered.err;
    const auto id = said["request_id"].get<std::string>();
    EXPECT_NE(unanswered.err.find("--request-id " + id), std::string::npos) << unanswered.err;
    ASSERT_TRUE(wait_until([&] { return seconds_since(cut) > 7.0; }, kGenerous, kPoll));
    const auto retried = bench.ctl({"--request-id", id, "plan", "append", leg}, 60'000);
    ASSERT_EQ(retried.exit_code, 0) << retried.out << retried.err << bench.logs();
    EXPECT_FALSE(Json::parse(retried.out, nullptr, false).value("replayed", false))
        << "the vehicle never had it: " << retried.out;
    const std::size_t appended = elements();
    EXPECT_GT(appended, before);

    // 2. The answer lost: the client is gone once the vehicle has the command (and the answer's way cut).
    // The record counts a command as it is admitted, and is read live; the ground link's counters are
    // published once a second and may not show the retry above yet.
    const auto recorded = [&] {
        return section(bench.status(), "status")["request_ids"].value("recorded", std::uint64_t{0});
    };
    const auto recorded_before = recorded();
    Subprocess lost({binary("client/airsegctl"), "--link", bench.ground_link(), "--timeout", "60000",
                     "--json", "--request-id", "lost-1", "plan", "append", leg},
                    {}, bench.dir().path());
    ASSERT_TRUE(
        wait_until([&] { return recorded() > recorded_before; }, kGenerous, std::chrono::milliseconds(20)))
        << lost.err() << bench.logs();
    (void)bench.link().ask("outage 3 ba");
    lost.signal(SIGKILL);
    (void)lost.wait_exit(std::chrono::seconds(5));
    ASSERT_TRUE(wait_until([&] { return elements() > appended; }, kGenerous, kPoll)) << bench.logs();
    const std::size_t appended_twice = elements();
    const auto again = bench.ctl({"--request-id", "lost-1", "plan", "append", leg}, 60'000);
    ASSERT_EQ(again.exit_code, 0) << again.out << again.err << bench.logs();
    EXPECT_EQ(Json::parse(again.out, nullptr, false).value("replayed", false), true) << again.out;
    EXPECT_EQ(elements(), appended_twice) << "the append was done twice";
    const auto ids = section(bench.status(), "status")["request_ids"];
    EXPECT_EQ(ids.value("replayed", 0), 1) << ids.dump();
    std::cout << "[ figures ] plan elements " << before << " -> " << appended
              << " (retried after no answer) -> " << appended_twice << " (its answer lost) -> " << elements()
              << " after its retry; record " << ids.dump() << "\n";
    expect_daemon_alive(bench);
}

TEST(SystemRadio, ARadioProfileGivenToBothEndsPacesTheLinkAndLongAnswersCross) {
    // 32-byte air packets with 8 bytes of overhead each: the air carries four fifths of what the port takes.
    // The daemon's status says what it paces for, and the answers cross without a byte dropped by a radio.
    // (These answers come one at a time, with round trips between them: even an end not told of the radio
    // does not fill its buffer here. tests/unit/linksim/radio_on_air_test.cpp drives the saturating case.)
    BenchOptions o;
    o.link_args = {"--packet", "32", "--packet-overhead", "8"};
    o.daemon_sets = {"groundlink.radio.packet=32", "groundlink.radio.packet_overhead=8"};
    SystemBench bench(o);
    ASSERT_TRUE(bench.wait_ready()) << bench.logs();
    const auto pacing = section(bench.status(), "groundlink")["pacing"];
    EXPECT_EQ(pacing.value("air_packet", 0), 32) << pacing.dump();
    EXPECT_EQ(pacing.value("air_packet_overhead", 0), 8) << pacing.dump();
    EXPECT_NEAR(pacing.value("carried_bytes_per_s", 0.0), 5760.0 * 32 / 40, 0.1) << pacing.dump();
    const std::vector<std::string> radio{"--radio", "packet=32,packet_overhead=8"};
    auto with_radio = [&](std::vector<std::string> args) {
        args.insert(args.begin(), radio.begin(), radio.end());
        return bench.ctl(args, 60'000);
    };
    std::size_t answer_bytes = 0;
    const auto params = with_radio({"param", "list"});
    ASSERT_EQ(params.exit_code, 0) << params.out << params.err << bench.logs();
    answer_bytes += params.out.size();
    for (int i = 0; i < 3; ++i) {
        const auto r = with_radio({"status"});
        ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
        answer_bytes += r.out.size();
    }
    const auto stats = bench.link().json("stats");
    const auto overflow = counter(stats, "/ab/overflow_dropped") + counter(stats, "/ba/overflow_dropped");
    std::cout << "[ figures ] 32-byte air packets, 8 bytes of overhead, told to both ends: " << answer_bytes
              << " bytes of answers, radio overflow " << overflow << " bytes; pacing " << pacing.dump()
              << "\n";
    EXPECT_EQ(overflow, 0u) << stats.dump();
    expect_daemon_alive(bench);
}

}  // namespace
}  // namespace airseg::test::sys
