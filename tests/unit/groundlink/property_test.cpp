// Property: for random loss, corruption, duplication, reordering and garbage, every Safe message is delivered
// exactly once and in order per channel, and nothing is delivered that was not sent.
#include <gtest/gtest.h>

#include <cstdlib>
#include <map>
#include <set>

#include "tests/unit/groundlink/sim_link.hpp"

namespace airseg::groundlink {
namespace {

constexpr std::uint64_t kSeedGroups = 6;

using namespace std::chrono_literals;

struct Sent {
    std::array<std::vector<std::uint32_t>, 4> safe;          // per channel, in order
    std::map<std::uint32_t, std::vector<std::uint8_t>> all;  // id -> bytes
};

void check_end(const test::Endpoint& rx, const Sent& sent, bool expect_all, std::uint64_t seed) {
    std::array<std::vector<std::uint32_t>, 4> got;
    std::set<std::uint32_t> fast_seen;
    for (const auto& d : rx.received) {
        ASSERT_GE(d.bytes.size(), 4U) << "seed " << seed;
        const std::uint32_t id = test::id_of(d.bytes);
        const auto it = sent.all.find(id);
        ASSERT_NE(it, sent.all.end()) << "seed " << seed << ": delivered a message never sent";
        ASSERT_EQ(it->second, d.bytes) << "seed " << seed << ": delivered bytes differ from the sent message";
        if (d.cls == MessageClass::Safe) {
            got[d.priority].push_back(id);
        } else {
            ASSERT_TRUE(fast_seen.insert(id).second) << "seed " << seed << ": Fast message delivered twice";
        }
    }
    for (std::size_t ch = 0; ch < 4; ++ch) {
        const auto& want = sent.safe[ch];
        ASSERT_LE(got[ch].size(), want.size()) << "seed " << seed << " channel " << ch << ": duplicates";
        for (std::size_t i = 0; i < got[ch].size(); ++i) {
            ASSERT_EQ(got[ch][i], want[i]) << "seed " << seed << " channel " << ch << " position " << i;
        }
        if (expect_all) {
            EXPECT_EQ(got[ch].size(), want.size())
                << "seed " << seed << " channel " << ch << ": not all delivered";
        }
    }
}

void run_seed(std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    auto uni = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
    test::Impairments imp;
    imp.loss = uni(0.0, 0.3);
    imp.byte_corrupt = uni(0.0, 1e-3);
    imp.duplicate = uni(0.0, 0.1);
    imp.reorder = uni(0.0, 0.2);
    imp.garbage = uni(0.0, 0.05);
    test::PathModel pm;
    pm.imp = imp;
    pm.rate = uni(2000.0, 12000.0);
    const bool keyed = seed % 3 != 0;
    TransportConfig a = test::base_config(1000 + seed, keyed);
    TransportConfig b = test::base_config(2000 + seed, keyed);
    a.link_rate_bytes_per_s = b.link_rate_bytes_per_s = pm.rate;
    // Every fourth seed runs two paths, split or redundant, the second with its own impairments.
    std::vector<test::PathModel> models{pm};
    if (seed % 4 == 1) {
        a.paths = b.paths = 2;
        a.path_mode = b.path_mode = seed % 8 == 1 ? PathMode::Split : PathMode::Redundant;
        b.split_tx_path = 1;
        test::PathModel second = pm;
        second.imp.loss = uni(0.0, 0.3);
        models.push_back(second);
    }
    test::SimLink link(a, b, models, seed);

    std::array<Sent, 2> sent;
    std::uint32_t next_id = 1;
    const TimePoint start = link.now();
    // Traffic for 40 s of simulated time, both directions, all channels, Safe and Fast.
    for (int burst = 0; burst < 40; ++burst) {
        for (int from = 0; from < 2; ++from) {
            const int n = static_cast<int>(rng() % 4);
            for (int k = 0; k < n; ++k) {
                const std::uint32_t id = next_id++;
                const auto prio = static_cast<std::uint8_t>(rng() % 4);
                const std::size_t size = 4 + rng() % (rng() % 5 == 0 ? 3000 : 200);
                auto msg = test::pattern(size, id);
                sent[static_cast<std::size_t>(from)].all[id] = msg;
                if (rng() % 3 == 0) {
                    link.end(from).core->send_fast(prio, static_cast<std::uint16_t>(rng() % 6), msg,
                                                   link.now());
                } else if (link.end(from).core->send_safe(prio, msg, link.now()) == SendResult::Accepted) {
                    sent[static_cast<std::size_t>(from)].safe[prio].push_back(id);
                }
            }
        }
        link.run_for(1s);
        ASSERT_FALSE(link.livelocked()) << "seed " << seed;
        // An attacker on the frequency: replays of frames recorded earlier, and random bytes.
        for (int to = 0; to < 2; ++to) {
            const auto& rec = link.recorded(1 - to);
            for (int k = 0; k < 3 && !rec.empty(); ++k) {
                link.inject(to, rng() % models.size(), rec[rng() % rec.size()]);
            }
            std::vector<std::uint8_t> junk(1 + rng() % 60);
            for (auto& byte : junk) {
                byte = static_cast<std::uint8_t>(rng());
            }
            link.inject(to, 0, junk);
        }
        if (::testing::Test::HasFatalFailure()) {
            return;
        }
    }
    check_end(link.b(), sent[0], false, seed);
    check_end(link.a(), sent[1], false, seed);
    // Then a clean link: everything must arrive.
    for (std::size_t p = 0; p < models.size(); ++p) {
        link.path(p).imp = test::Impairments{};
    }
    link.run_until(start + 200s, [&] {
        return link.a().core->safe_pending(0) + link.a().core->safe_pending(1) +
                   link.a().core->safe_pending(2) + link.a().core->safe_pending(3) +
                   link.b().core->safe_pending(0) + link.b().core->safe_pending(1) +
                   link.b().core->safe_pending(2) + link.b().core->safe_pending(3) ==
               0;
    });
    ASSERT_FALSE(link.livelocked()) << "seed " << seed;
    check_end(link.b(), sent[0], true, seed);
    check_end(link.a(), sent[1], true, seed);
    EXPECT_EQ(link.a().core->stats().peer_restarts, 0U) << "seed " << seed;
    EXPECT_EQ(link.b().core->stats().peer_restarts, 0U) << "seed " << seed;
    const auto& s = link.b().core->stats();  // the impairments and the attacker did reach the core
    EXPECT_GT(s.replays + s.mac_failures + s.crc_errors + s.framing_errors, 0U) << "seed " << seed;
}

// The seeds in six cases of their own (seed k in case (k - 1) mod 6): under qemu-arm on armel, with no FPU
// and the rest of the suite beside it, the 24 seeds as one case ran past its 60-s limit.
class GroundlinkTransportProperty : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(GroundlinkTransportProperty, SafeExactlyOnceInOrderUnderRandomImpairments) {
    // AIRSEG_PROPERTY_SEEDS=n runs more seeds (the default keeps the suite fast).
    const char* env = std::getenv("AIRSEG_PROPERTY_SEEDS");
    const std::uint64_t seeds = env != nullptr ? std::strtoull(env, nullptr, 10) : 24;
    for (std::uint64_t seed = 1 + GetParam(); seed <= seeds; seed += kSeedGroups) {
        run_seed(seed);
        if (HasFatalFailure()) {
            return;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Seeds, GroundlinkTransportProperty, ::testing::Range<std::uint64_t>(0, kSeedGroups));

}  // namespace
}  // namespace airseg::groundlink
