// The core end to end, two instances in simulated time (sim_link.hpp).
#include <gtest/gtest.h>

#include "services/groundlink/transport/cobs.hpp"
#include "services/groundlink/transport/frame.hpp"
#include "tests/unit/groundlink/sim_link.hpp"

namespace airseg::groundlink {
namespace {

using namespace std::chrono_literals;
using test::base_config;
using test::pattern;
using test::SimLink;

std::vector<test::PathModel> one_path(test::Impairments imp = {}) {
    test::PathModel p;
    p.imp = imp;
    return {p};
}

bool has_event(const test::Endpoint& e, TransportEvent::Kind k) {
    return std::any_of(e.events.begin(), e.events.end(),
                       [k](const TransportEvent& ev) { return ev.kind == k; });
}

std::size_t count_safe(const test::Endpoint& e, std::uint8_t prio) {
    return static_cast<std::size_t>(std::count_if(
        e.received.begin(), e.received.end(),
        [prio](const Delivered& d) { return d.cls == MessageClass::Safe && d.priority == prio; }));
}

/// Offers `a` 40 KB of bulk: 40 messages of 1000 bytes on the lowest priority.
void offer_bulk(SimLink& link) {
    for (std::uint32_t i = 0; i < 40; ++i) {
        link.a().core->send_safe(3, pattern(1000, i), link.now());
    }
}

TEST(GroundlinkTransportConfig, ValidateNamesEachProblem) {
    EXPECT_TRUE(base_config(1).validate().empty());
    TransportConfig c = base_config(1);
    c.paths = 3;
    c.boot_nonce = 0;
    c.safe_window = 500;
    const auto e = c.validate();
    ASSERT_EQ(e.size(), 4U);  // paths, single-needs-1-path, window, nonce
    EXPECT_NE(e[0].find("paths"), std::string::npos);
    EXPECT_THROW(Transport(c, TimePoint{}), std::invalid_argument);
    TransportConfig split = base_config(1);
    split.path_mode = PathMode::Split;
    EXPECT_FALSE(split.validate().empty());
    split.paths = 2;
    EXPECT_TRUE(split.validate().empty());
}

TEST(GroundlinkTransport, HandshakeThenSafeBothWaysAuthenticated) {
    SimLink link(base_config(0x1111), base_config(0x2222), one_path(), 1);
    const auto m1 = pattern(300, 1);
    const auto m2 = pattern(3000, 2);
    ASSERT_EQ(link.a().core->send_safe(0, m1, link.now()), SendResult::Accepted);
    ASSERT_EQ(link.b().core->send_safe(2, m2, link.now()), SendResult::Accepted);
    link.run_for(5s);
    ASSERT_FALSE(link.livelocked());
    ASSERT_EQ(link.b().received.size(), 1U);
    EXPECT_EQ(link.b().received[0].bytes, m1);
    ASSERT_EQ(link.a().received.size(), 1U);
    EXPECT_EQ(link.a().received[0].bytes, m2);
    EXPECT_EQ(link.a().received[0].priority, 2);
    for (int i = 0; i < 2; ++i) {
        const auto& s = link.end(i).core->stats();
        EXPECT_TRUE(s.authenticated);
        EXPECT_TRUE(link.end(i).core->link_up());
        EXPECT_TRUE(link.end(i).core->session_established());
        EXPECT_EQ(s.mac_failures, 0U);
        EXPECT_TRUE(has_event(link.end(i), TransportEvent::Kind::SessionEstablished));
        EXPECT_TRUE(has_event(link.end(i), TransportEvent::Kind::LinkUp));
    }
    EXPECT_GT(link.a().core->stats().rtt_samples, 0U);
}

// The vehicle holds two keys; a ground end holding either gets a session bound to it, and one holding
// neither never does.
TEST(GroundlinkTransport, ASecondKeyIsAcceptedAndTheSessionSaysWhichKey) {
    auto key_of = [](std::uint8_t seed) {
        std::array<std::uint8_t, kKeyBytes> k{};
        for (std::size_t i = 0; i < k.size(); ++i) {
            k[i] = static_cast<std::uint8_t>(seed + i * 13);
        }
        return k;
    };
    TransportConfig vehicle = base_config(0x10);
    vehicle.key = key_of(1);
    vehicle.second_key = key_of(2);
    for (std::uint8_t ground_key : {1, 2, 3}) {
        TransportConfig ground = base_config(0x20 + ground_key);
        ground.key = key_of(ground_key);
        SimLink link(vehicle, ground, one_path(), ground_key);
        link.b().core->send_safe(0, pattern(50, 7), link.now());
        link.run_for(5s);
        if (ground_key == 3) {
            EXPECT_FALSE(link.a().core->session_established());
            EXPECT_TRUE(link.a().received.empty());
            EXPECT_GT(link.a().core->stats().mac_failures, 0U);
            continue;
        }
        ASSERT_TRUE(link.a().core->session_established()) << "key " << int{ground_key};
        EXPECT_EQ(link.a().core->session_key(), ground_key - 1U);
        ASSERT_EQ(count_safe(link.a(), 0), 1U);
        link.a().core->send_safe(1, pattern(60, 8), link.now());
        link.run_for(3s);
        EXPECT_EQ(count_safe(link.b(), 1), 1U) << "the vehicle answers with the session's key";
    }
    TransportConfig bad = vehicle;
    bad.second_key = bad.key;
    EXPECT_FALSE(bad.validate().empty());
    bad.key.reset();
    EXPECT_FALSE(bad.validate().empty());
}

TEST(GroundlinkTransport, WithoutKeyStatsSayUnauthenticated) {
    SimLink link(base_config(5, false), base_config(6, false), one_path(), 2);
    link.a().core->send_safe(1, pattern(50, 9), link.now());
    link.run_for(3s);
    ASSERT_EQ(link.b().received.size(), 1U);
    EXPECT_FALSE(link.a().core->stats().authenticated);
    EXPECT_FALSE(link.b().core->stats().authenticated);
}

// A ground end tells "not authorised" from "no link" by these counters: each mismatch shows on the end that
// must say so, and a matching pair (or a damaged frame) counts none.
TEST(GroundlinkTransport, AKeyMismatchIsCountedOnTheEndThatHearsIt) {
    auto key_of = [](std::uint8_t seed) {
        std::array<std::uint8_t, kKeyBytes> k{};
        k.fill(seed);
        return k;
    };
    struct Case {
        const char* what;
        std::optional<std::array<std::uint8_t, kKeyBytes>> vehicle, ground;
        std::uint64_t LinkStats::*counter;
    };
    const Case cases[] = {
        {"the vehicle has a key, the ground none", key_of(1), std::nullopt, &LinkStats::frames_needing_key},
        {"the ground has a key, the vehicle none", std::nullopt, key_of(1), &LinkStats::hellos_without_key},
        {"different keys", key_of(1), key_of(2), &LinkStats::hellos_with_other_key},
    };
    for (const auto& c : cases) {
        TransportConfig vehicle = base_config(0x30, false);
        vehicle.key = c.vehicle;
        TransportConfig ground = base_config(0x40, false);
        ground.key = c.ground;
        SimLink link(vehicle, ground, one_path(), 3);
        link.b().core->send_safe(0, pattern(50, 7), link.now());
        link.run_for(3s);
        EXPECT_FALSE(link.b().core->session_established()) << c.what;
        EXPECT_GT(link.b().core->stats().*c.counter, 0U) << c.what;
    }
    // A matching pair under byte corruption: damaged frames are not mistaken for a mismatch.
    for (const bool keyed : {false, true}) {
        test::Impairments imp;
        imp.byte_corrupt = 2e-3;
        SimLink link(base_config(0x50, keyed), base_config(0x60, keyed), one_path(imp), 4);
        for (std::uint32_t i = 0; i < 20; ++i) {
            link.a().core->send_safe(1, pattern(200, i), link.now());
            link.b().core->send_safe(1, pattern(200, i + 100), link.now());
        }
        link.run_for(20s);
        for (const auto* end : {&link.a(), &link.b()}) {
            const auto& s = end->core->stats();
            EXPECT_GT(s.crc_errors, 0U) << "the corruption reached the frames";
            EXPECT_EQ(s.frames_needing_key + s.hellos_without_key + s.hellos_with_other_key, 0U)
                << (keyed ? "keyed" : "unkeyed");
        }
    }
}

TEST(GroundlinkTransport, PacingNeverExceedsRateTimesElapsedPlusOneFrame) {
    SimLink link(base_config(1), base_config(2), one_path(), 3);
    for (std::uint32_t i = 0; i < 60; ++i) {
        link.a().core->send_safe(3, pattern(1000, i), link.now());
        link.a().core->send_fast(1, static_cast<std::uint16_t>(i % 5), pattern(40, i), link.now());
    }
    const TimePoint start = link.now();
    bool violated = false;
    link.run_until(start + 10s, [&] {
        const double elapsed = std::chrono::duration<double>(link.now() - start).count();
        const double allowed = 5760.0 * elapsed + static_cast<double>(link.largest_frame());
        violated = violated || static_cast<double>(link.written(0, 0)) > allowed + 1.0;
        return false;
    });
    EXPECT_FALSE(violated);
    EXPECT_FALSE(link.livelocked());
    EXPECT_GT(link.written(0, 0), 5760U * 10U * 8U / 10U);  // and it does use the link
}

TEST(GroundlinkTransport, UrgentMessageOvertakesBulkWithinAFewFrameTimes) {
    SimLink link(base_config(1), base_config(2), one_path(), 4);
    link.run_for(2s);  // handshake
    for (std::uint32_t i = 0; i < 40; ++i) {
        link.a().core->send_safe(3, pattern(2000, i), link.now());
    }
    link.run_for(3s);  // bulk is flowing
    const TimePoint sent = link.now();
    link.a().core->send_safe(0, pattern(20, 999), link.now());
    TimePoint arrived{};
    link.run_until(sent + 5s, [&] {
        if (count_safe(link.b(), 0) == 1) {
            arrived = link.now();
            return true;
        }
        return false;
    });
    ASSERT_NE(arrived, TimePoint{});
    // A frame in flight, the control frame itself and the radio latency; frames are capped at
    // latency_frame_payload while urgent traffic is active, so this is a few tens of milliseconds.
    EXPECT_LT(arrived - sent, 250ms);
    EXPECT_LT(count_safe(link.b(), 3), 40U);  // bulk was still going
}

TEST(GroundlinkTransport, LowerPriorityGetsItsMinimumShare) {
    TransportConfig a = base_config(1);
    a.min_share = {0.0, 0.0, 0.0, 0.1, 0, 0, 0, 0};
    SimLink link(a, base_config(2), one_path(), 5);
    for (std::uint32_t i = 0; i < 200; ++i) {
        link.a().core->send_safe(0, pattern(1000, i), link.now());
        link.a().core->send_safe(3, pattern(1000, 10000 + i), link.now());
    }
    link.run_for(30s);
    const std::size_t high = count_safe(link.b(), 0);
    const std::size_t low = count_safe(link.b(), 3);
    EXPECT_GT(high, 50U);
    EXPECT_GT(low, 0U);
    const double low_share = static_cast<double>(low) / static_cast<double>(high + low);
    EXPECT_GT(low_share, 0.06);
    EXPECT_LT(low_share, 0.2);
}

TEST(GroundlinkTransport, FastFreshestWinsEndToEnd) {
    SimLink link(base_config(1), base_config(2), one_path(), 6);
    link.run_for(2s);
    for (std::uint32_t v = 0; v < 50; ++v) {
        link.a().core->send_fast(1, 7, pattern(30, v), link.now());  // all before the next poll
    }
    link.run_for(1s);
    std::vector<std::uint32_t> got;
    for (const auto& d : link.b().received) {
        if (d.cls == MessageClass::Fast) {
            got.push_back(test::id_of(d.bytes));
            EXPECT_EQ(d.topic, 7);
        }
    }
    ASSERT_EQ(got.size(), 1U);
    EXPECT_EQ(got[0], 49U);
    EXPECT_EQ(link.a().core->stats().tx_fast.replaced, 49U);
}

TEST(GroundlinkTransport, RttAndRtoFollowTheLinkLatency) {
    test::Impairments slow;
    slow.latency = 150ms;
    SimLink link(base_config(1), base_config(2), one_path(slow), 7);
    for (std::uint32_t i = 0; i < 100; ++i) {
        link.a().core->send_safe(1, pattern(100, i), link.now());
    }
    link.run_for(20s);
    const auto& s = link.a().core->stats();
    ASSERT_GT(s.rtt_samples, 10U);
    EXPECT_GT(s.srtt_ms, 300.0);  // two one-way latencies plus serialization
    EXPECT_LT(s.srtt_ms, 700.0);
    EXPECT_GE(s.rto_ms, s.srtt_ms);
    EXPECT_LE(s.rto_ms, 2000.0);
    EXPECT_EQ(s.tx_safe.retransmissions, 0U);  // no spurious timeouts on a clean slow link
    EXPECT_EQ(count_safe(link.b(), 1), 100U);
}

TEST(GroundlinkTransport, PeerRestartIsDetectedAndBothResynchronize) {
    SimLink link(base_config(0xA), base_config(0xB), one_path(), 8);
    for (std::uint32_t i = 0; i < 5; ++i) {
        link.a().core->send_safe(0, pattern(100, i), link.now());
    }
    link.run_for(3s);
    ASSERT_EQ(count_safe(link.b(), 0), 5U);
    link.restart(1, base_config(0xBB));  // B comes back with a new boot nonce
    link.b().received.clear();
    link.b().events.clear();
    for (std::uint32_t i = 5; i < 10; ++i) {
        link.a().core->send_safe(0, pattern(100, i), link.now());
        link.b().core->send_safe(0, pattern(100, 100 + i), link.now());
    }
    link.run_for(5s);
    EXPECT_TRUE(has_event(link.a(), TransportEvent::Kind::PeerRestarted));
    EXPECT_EQ(link.a().core->stats().peer_restarts, 1U);
    EXPECT_TRUE(has_event(link.b(), TransportEvent::Kind::SessionEstablished));
    ASSERT_EQ(count_safe(link.b(), 0), 5U);
    for (std::uint32_t i = 0; i < 5; ++i) {
        EXPECT_EQ(test::id_of(link.b().received[i].bytes), 5 + i);
    }
    EXPECT_EQ(count_safe(link.a(), 0), 5U);
    EXPECT_TRUE(link.a().core->link_up());
    EXPECT_TRUE(link.b().core->link_up());
}

// A restarted peer may hear the survivor's session hello (still in the air, or a reply to its previous
// incarnation) before anything else, and then echo the survivor's session nonce in its own hellos. The
// survivor must still challenge it, or the new incarnation is never heard while the survivor keeps talking
// to the one that died (found by fuzz_groundlink_transport).
TEST(GroundlinkTransport, RestartedPeerThatHeardTheOldSessionsHelloFirstIsStillAccepted) {
    SimLink link(base_config(0xA), base_config(0xB), one_path(), 9);
    link.run_for(3s);
    ASSERT_TRUE(link.a().core->session_established() && link.b().core->session_established());
    // B's latest hello: its session reply to A's old incarnation.
    std::vector<std::uint8_t> session_hello;
    for (const auto& wire : link.recorded(1)) {
        const auto plain = cobs_decode(std::span(wire).first(wire.size() - 1));
        if (plain && frame::kind_of(*plain) == frame::Kind::Hello) {
            session_hello = wire;
        }
    }
    ASSERT_FALSE(session_hello.empty());

    link.restart(0, base_config(0xAA));
    link.a().received.clear();
    link.inject(0, 0, session_hello);  // the first thing the new incarnation hears
    for (std::uint32_t i = 0; i < 3; ++i) {
        link.b().core->send_safe(0, pattern(100, i), link.now());
        link.a().core->send_safe(0, pattern(100, 10 + i), link.now());
    }
    link.run_for(10s);
    EXPECT_TRUE(link.a().core->session_established());
    EXPECT_EQ(link.b().core->stats().peer_restarts, 1U);
    EXPECT_EQ(count_safe(link.a(), 0), 3U) << "the survivor's messages reach the new incarnation";
    EXPECT_EQ(count_safe(link.b(), 0), 3U);
}

// A hello recorded from an incarnation that has since restarted, replayed to the survivor, draws a challenge
// that the live incarnation must ignore: answering it would renegotiate the live session and deliver the
// survivor's in-flight messages a second time (found by fuzz_groundlink_transport).
TEST(GroundlinkTransport, ReplayedHelloOfADeadIncarnationLeavesTheLiveSessionAlone) {
    SimLink link(base_config(0xA), base_config(0xB), one_path(), 10);
    link.run_for(3s);
    std::vector<std::vector<std::uint8_t>> old_hellos;
    for (const auto& wire : link.recorded(0)) {
        const auto plain = cobs_decode(std::span(wire).first(wire.size() - 1));
        if (plain && frame::kind_of(*plain) == frame::Kind::Hello) {
            old_hellos.push_back(wire);
        }
    }
    ASSERT_FALSE(old_hellos.empty());
    link.restart(0, base_config(0xAA));
    link.a().received.clear();
    link.run_for(5s);
    ASSERT_TRUE(link.a().core->session_established() && link.b().core->session_established());
    ASSERT_EQ(link.b().core->stats().peer_restarts, 1U);

    for (std::uint32_t i = 0; i < 20; ++i) {
        link.b().core->send_safe(0, pattern(100, i), link.now());
    }
    for (const auto& hello : old_hellos) {
        link.inject(1, 0, hello);
        link.run_for(200ms);
    }
    link.run_for(10s);
    EXPECT_EQ(link.b().core->stats().peer_restarts, 1U) << "the replay renegotiated the session";
    ASSERT_EQ(count_safe(link.a(), 0), 20U);
    for (std::uint32_t i = 0; i < 20; ++i) {
        EXPECT_EQ(test::id_of(link.a().received[i].bytes), i);
    }
}

// A fresh incarnation that first hears a recording of the survivor's hello from an older session echoes a
// nonce the survivor no longer uses, and the survivor rightly ignores it; after a few unanswered hellos the
// fresh end echoes nothing and is challenged (found by fuzz_groundlink_transport).
TEST(GroundlinkTransport, FreshPeerMisledByAnOldRecordingStillGetsASession) {
    SimLink link(base_config(0xA), base_config(0xB), one_path(), 11);
    link.run_for(3s);
    std::vector<std::uint8_t> first_session_hello;
    for (const auto& wire : link.recorded(1)) {
        const auto plain = cobs_decode(std::span(wire).first(wire.size() - 1));
        if (plain && frame::kind_of(*plain) == frame::Kind::Hello) {
            first_session_hello = wire;
        }
    }
    ASSERT_FALSE(first_session_hello.empty());
    link.restart(0, base_config(0xAA));  // B's session nonce changes with the new session
    link.run_for(5s);
    ASSERT_EQ(link.b().core->stats().peer_restarts, 1U);

    link.restart(0, base_config(0xAAA));
    link.a().received.clear();
    link.inject(0, 0, first_session_hello);
    for (std::uint32_t i = 0; i < 3; ++i) {
        link.b().core->send_safe(0, pattern(100, i), link.now());
    }
    link.run_for(15s);
    EXPECT_TRUE(link.a().core->session_established());
    EXPECT_EQ(link.b().core->stats().peer_restarts, 2U);
    EXPECT_EQ(count_safe(link.a(), 0), 3U);
}

TEST(GroundlinkTransport, ForgedAndReplayedFramesAreNeverDelivered) {
    SimLink link(base_config(0x10), base_config(0x20), one_path(), 9);
    for (std::uint32_t i = 0; i < 20; ++i) {
        link.a().core->send_safe(0, pattern(200, i), link.now());
        link.a().core->send_fast(1, 3, pattern(30, 500 + i), link.now());
    }
    link.run_for(5s);
    const std::size_t delivered = link.b().received.size();
    ASSERT_EQ(count_safe(link.b(), 0), 20U);

    // Replays: every frame A ever wrote, again, in order and reversed.
    const auto recorded = link.recorded(0);
    for (const auto& f : recorded) {
        link.inject(1, 0, f);
    }
    for (auto it = recorded.rbegin(); it != recorded.rend(); ++it) {
        link.inject(1, 0, *it);
    }
    EXPECT_EQ(link.b().received.size(), delivered);
    EXPECT_GT(link.b().core->stats().replays, 0U);

    // Forgeries: a peer with the wrong key, and random bytes.
    TransportConfig wrong = base_config(0x10);
    (*wrong.key)[0] ^= 1;
    SimLink evil(wrong, base_config(0x30), one_path(), 10);
    evil.a().core->send_safe(0, pattern(50, 77), evil.now());
    evil.run_for(2s);
    std::mt19937 rng(3);
    for (const auto& f : evil.recorded(0)) {
        link.inject(1, 0, f);
    }
    for (int i = 0; i < 200; ++i) {
        std::vector<std::uint8_t> junk(1 + rng() % 80);
        for (auto& b : junk) {
            b = static_cast<std::uint8_t>(rng());
        }
        link.inject(1, 0, junk);
    }
    EXPECT_EQ(link.b().received.size(), delivered);
    EXPECT_GT(link.b().core->stats().mac_failures, 0U);
    // The session survives: a genuine message still gets through.
    link.a().core->send_safe(0, pattern(10, 4242), link.now());
    link.run_for(3s);
    EXPECT_EQ(count_safe(link.b(), 0), 21U);
    EXPECT_FALSE(has_event(link.b(), TransportEvent::Kind::PeerRestarted));
}

test::PathModel clean_path() {
    return test::PathModel{};
}

TransportConfig dual(std::uint64_t nonce, PathMode mode, std::size_t tx_path) {
    TransportConfig c = base_config(nonce);
    c.paths = 2;
    c.path_mode = mode;
    c.split_tx_path = tx_path;
    return c;
}

std::uint64_t bulk_bytes_delivered(PathMode mode, std::size_t paths, Duration run, std::uint64_t seed) {
    TransportConfig a = paths == 1 ? base_config(1) : dual(1, mode, 0);
    TransportConfig b = paths == 1 ? base_config(2) : dual(2, mode, 1);
    std::vector<test::PathModel> models(paths, clean_path());
    SimLink link(a, b, models, seed);
    std::uint32_t next = 0;
    const TimePoint end = link.now() + run;
    while (link.now() < end) {
        while (link.a().core->send_safe(3, pattern(1000, next), link.now()) == SendResult::Accepted) {
            ++next;
        }
        link.run_for(1s);
    }
    std::uint64_t bytes = 0;
    for (const auto& d : link.b().received) {
        bytes += d.bytes.size();
    }
    return bytes;
}

TEST(GroundlinkTransport, SplitModeNearlyDoublesThroughput) {
    const auto single = bulk_bytes_delivered(PathMode::Single, 1, 30s, 11);
    const auto split = bulk_bytes_delivered(PathMode::Split, 2, 30s, 11);
    EXPECT_GT(static_cast<double>(single), 0.9 * 5760.0 * 28.0);
    EXPECT_GT(static_cast<double>(split), 1.9 * static_cast<double>(single));
}

TEST(GroundlinkTransport, SplitFallsBackWhenAPairGoesSilentAndReturns) {
    TransportConfig a = dual(1, PathMode::Split, 0);
    TransportConfig b = dual(2, PathMode::Split, 1);
    a.split_borrow = b.split_borrow = false;  // so path 1 carries A's data only while falling back
    SimLink link(a, b, {clean_path(), clean_path()}, 12);
    link.run_for(3s);
    link.path(0).a_to_b_up = false;  // A's transmit pair dies
    for (std::uint32_t i = 0; i < 30; ++i) {
        link.a().core->send_safe(1, pattern(500, i), link.now());
    }
    link.run_for(15s);
    EXPECT_EQ(count_safe(link.b(), 1), 30U);
    EXPECT_TRUE(has_event(link.b(), TransportEvent::Kind::PathDown));
    const auto via_fallback = link.written(0, 1);
    EXPECT_GT(via_fallback, 30U * 500U);
    link.path(0).a_to_b_up = true;  // recovers
    link.run_for(5s);
    const auto before = link.written(0, 1);
    for (std::uint32_t i = 30; i < 60; ++i) {
        link.a().core->send_safe(1, pattern(500, i), link.now());
    }
    link.run_for(10s);
    EXPECT_EQ(count_safe(link.b(), 1), 60U);
    EXPECT_LT(link.written(0, 1) - before, 30U * 500U / 4);  // the bulk went back on path 0
    EXPECT_TRUE(link.a().core->stats().path[0].peer_hears);
}

TEST(GroundlinkTransport, RedundantModeDropsDuplicatesAndSurvivesOnePathDying) {
    SimLink link(dual(1, PathMode::Redundant, 0), dual(2, PathMode::Redundant, 0),
                 {clean_path(), clean_path()}, 13);
    for (std::uint32_t i = 0; i < 20; ++i) {
        link.a().core->send_safe(0, pattern(200, i), link.now());
    }
    link.run_for(5s);
    EXPECT_EQ(count_safe(link.b(), 0), 20U);
    EXPECT_GT(link.b().core->stats().replays, 10U);  // the second copies
    link.path(1).a_to_b_up = false;
    link.path(1).b_to_a_up = false;
    for (std::uint32_t i = 20; i < 40; ++i) {
        link.a().core->send_safe(0, pattern(200, i), link.now());
    }
    link.run_for(10s);
    EXPECT_EQ(count_safe(link.b(), 0), 40U);
    EXPECT_TRUE(link.a().core->link_up());
}

TEST(GroundlinkTransport, FrameSizeShrinksUnderCorruption) {
    test::Impairments noisy;
    noisy.byte_corrupt = 1e-3;
    SimLink link(base_config(1), base_config(2), one_path(noisy), 14);
    for (std::uint32_t i = 0; i < 200; ++i) {
        link.a().core->send_safe(3, pattern(1000, i), link.now());
    }
    link.run_for(30s);
    const auto& s = link.a().core->stats();
    EXPECT_GT(s.peer_suggested_payload, 60U);
    EXPECT_LT(s.peer_suggested_payload, 300U);
    EXPECT_LT(s.frame_payload, 300U);
    EXPECT_GT(count_safe(link.b(), 3), 50U);
}

// 2 % of the bytes lost each way: a 1000-byte segment would never arrive whole, so the ends measure the error
// rate, report it, and the sender switches to shards with parity; messages keep arriving, in order.
TEST(GroundlinkTransport, UnderByteLossFramesTravelAsShardsAndMessagesGetThrough) {
    test::Impairments lossy;
    lossy.byte_loss = 0.02;
    SimLink link(base_config(1), base_config(2), one_path(lossy), 21);
    offer_bulk(link);
    link.run_for(60s);
    const auto& a = link.a().core->stats();
    const auto& b = link.b().core->stats();
    EXPECT_NEAR(b.byte_error_rate, 0.02, 0.008) << "b measures a's frames";
    EXPECT_NEAR(a.peer_byte_error_rate, b.byte_error_rate, 0.004) << "and reports it";
    EXPECT_TRUE(a.fec);
    EXPECT_GT(a.fec_frames_sent, 20U);
    EXPECT_GT(b.fec_frames_repaired, 10U) << "parity rebuilt frames whose data shards were hit";
    EXPECT_GE(count_safe(link.b(), 3), 25U) << "most of 40 KB in a minute at 5760 B/s";

    // The same link without forward error correction: small plain frames, far fewer messages.
    auto plain_a = base_config(1);
    plain_a.fec = false;
    auto plain_b = base_config(2);
    plain_b.fec = false;
    SimLink plain(plain_a, plain_b, one_path(lossy), 21);
    offer_bulk(plain);
    plain.run_for(60s);
    EXPECT_FALSE(plain.a().core->stats().fec);
    EXPECT_EQ(plain.a().core->stats().fec_frames_sent, 0U);
    EXPECT_LT(count_safe(plain.b(), 3), count_safe(link.b(), 3));
}

TEST(GroundlinkTransport, LostAirPacketsKeepFramesPlainNotShards) {
    // A radio that loses whole air packets: frames vanish about as often as they arrive damaged. Parity
    // sized for independent byte errors would not repair that, so the receiver reports the errors as
    // bursty and the sender keeps plain frames. Byte errors alone make shards pay.
    test::Impairments packets;
    packets.air_packet_loss = 0.3;
    SimLink link(base_config(1), base_config(2), one_path(packets), 31);
    offer_bulk(link);
    // Frames across a lost packet arrive damaged, so the first error rates may favour shards for a few
    // seconds; the vanished ones soon say otherwise, and shards stay off.
    link.run_for(20s);
    const auto groups_early = link.a().core->stats().fec_frames_sent;
    link.run_for(40s);
    EXPECT_GT(link.b().core->stats().byte_error_rate, 0.0);
    EXPECT_FALSE(link.a().core->stats().fec);
    EXPECT_EQ(link.a().core->stats().fec_frames_sent, groups_early) << "shards again after the first 20 s";
    // Without counting vanished frames this draw sends 27 groups, and 15 to 34 in most others.
    EXPECT_LE(groups_early, 10U);
    EXPECT_GE(count_safe(link.b(), 3), 10U);

    test::Impairments bytes;
    bytes.byte_loss = 0.01;
    SimLink alone(base_config(1), base_config(2), one_path(bytes), 31);
    offer_bulk(alone);
    alone.run_for(60s);
    EXPECT_TRUE(alone.a().core->stats().fec);
}

TEST(GroundlinkTransport, AnEndThatHearsNoAcknowledgementsProbesInsteadOfFillingTheAir) {
    // b hears a but a hears nothing for a minute: a's window goes out once, then one probe per timeout. If
    // every outstanding segment timed out in turn, a would resend its window at the full link rate and, with
    // b's own frames on the same half-duplex air, the radios would queue minutes of frames.
    SimLink link(base_config(1), base_config(2), one_path(), 16);
    link.run_for(2s);
    ASSERT_TRUE(link.a().core->session_established());
    for (std::uint32_t i = 0; i < 40; ++i) {
        ASSERT_EQ(link.a().core->send_safe(3, pattern(2000, i), link.now()), SendResult::Accepted);
    }
    link.path(0).b_to_a_up = false;
    const std::uint64_t before = link.written(0, 0);
    link.run_for(60s);
    const std::uint64_t during = link.written(0, 0) - before;
    EXPECT_LT(during, 5760U * 60U / 4U);  // the window once (about 64 kB) and probes, not 345 kB
    EXPECT_LT(link.air_backlog(0), 1s);
    link.path(0).b_to_a_up = true;
    link.run_until(link.now() + 60s, [&] { return count_safe(link.b(), 3) == 40; });
    ASSERT_EQ(count_safe(link.b(), 3), 40U);
    for (std::uint32_t i = 0; i < 40; ++i) {
        EXPECT_EQ(link.b().received[i].bytes, pattern(2000, i));
    }
    EXPECT_FALSE(link.livelocked());
}

TEST(GroundlinkTransport, AnOversizedMessageIsDroppedCountedAndTheChannelGoesOn) {
    // A peer configured for larger messages (or a misbehaving one): the receiver drops what exceeds its own
    // max_message_size, counts it, and still acknowledges the segments so the messages behind it flow.
    TransportConfig big = base_config(1);
    big.max_message_size = 64 * 1024;
    TransportConfig small = base_config(2);
    small.max_message_size = 1024;
    SimLink link(big, small, one_path(), 17);
    link.run_for(2s);
    ASSERT_TRUE(link.b().core->session_established());
    ASSERT_EQ(link.a().core->send_safe(3, pattern(4000, 1), link.now()), SendResult::Accepted);
    ASSERT_EQ(link.a().core->send_safe(3, pattern(100, 2), link.now()), SendResult::Accepted);
    link.a().core->send_fast(1, 7, pattern(3000, 3), link.now());
    link.run_until(link.now() + 30s,
                   [&] { return count_safe(link.b(), 3) == 1 && link.a().core->safe_pending(3) == 0; });
    ASSERT_EQ(link.b().received.size(), 1U);
    EXPECT_EQ(link.b().received[0].bytes, pattern(100, 2));
    EXPECT_EQ(link.b().core->stats().oversized, 2U);
    EXPECT_EQ(link.a().core->safe_pending(3), 0U);
    EXPECT_EQ(link.a().core->stats().oversized, 0U);
}

TEST(GroundlinkTransport, LinkGoesDownAfterSilenceAndComesBack) {
    SimLink link(base_config(1), base_config(2), one_path(), 15);
    link.run_for(3s);
    ASSERT_TRUE(link.a().core->link_up());
    link.path(0).a_to_b_up = false;
    link.path(0).b_to_a_up = false;
    link.run_for(5s);
    EXPECT_FALSE(link.a().core->link_up());
    EXPECT_TRUE(has_event(link.a(), TransportEvent::Kind::LinkDown));
    link.path(0).a_to_b_up = true;
    link.path(0).b_to_a_up = true;
    link.run_for(3s);
    EXPECT_TRUE(link.a().core->link_up());
    EXPECT_TRUE(link.b().core->link_up());
}

}  // namespace
}  // namespace airseg::groundlink
