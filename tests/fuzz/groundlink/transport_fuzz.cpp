// Fuzzes the ground-link transport's receive path two ways; the first input byte picks one.
//
// Scenario mode (even first byte): the input is a script for two keyed Transport cores on the simulated radio
// link of the property tests (tests/unit/groundlink/sim_link.hpp): impairment levels, traffic, outages of
// one or both directions lasting up to 90 s, and restarts of either end. What must hold for every script:
//  - per channel, each incarnation of an end receives the other end's Safe messages in order, without
//    duplicates, and only messages that were sent, byte for byte (Fast: sent, at most once);
//  - after the script, on a clean link, both ends hold a session and every Safe message still queued is
//    delivered within 200 simulated seconds (no session stuck one way, no stalled channel).
// Raw mode (odd first byte): the rest of the input is fed as radio bytes, in input-derived chunks, to a keyed
// and an unkeyed core; the keyed one must never deliver anything (no key, no message), neither may crash.
#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <span>
#include <vector>

#include "tests/fuzz/require.hpp"
#include "tests/unit/groundlink/sim_link.hpp"

namespace {

using namespace airseg::groundlink;
using namespace std::chrono_literals;
using airseg::TimePoint;

// Consumes the input front to back; past the end it yields zeros, so every input is a complete script.
class Script {
  public:
    explicit Script(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
    std::uint8_t byte() { return pos_ < bytes_.size() ? bytes_[pos_++] : 0; }
    std::uint32_t u32() {
        std::uint32_t v = 0;
        for (int i = 0; i < 4; ++i) {
            v |= static_cast<std::uint32_t>(byte()) << (8 * i);
        }
        return v;
    }
    double fraction(double max) { return max * byte() / 255.0; }
    bool done() const { return pos_ >= bytes_.size(); }

  private:
    std::span<const std::uint8_t> bytes_;
    std::size_t pos_ = 0;
};

struct Incarnation {
    std::map<std::uint32_t, std::vector<std::uint8_t>> sent;  // id -> bytes (Safe and Fast)
    std::array<std::vector<std::uint32_t>, 4> safe_order;     // ids per channel, in send order
};

// What one end has received, checked against what the peer's incarnations sent.
void check_received(const test::Endpoint& rx, const std::vector<Incarnation>& senders) {
    std::array<std::map<std::size_t, std::vector<std::uint32_t>>, 4>
        safe_got;  // channel -> incarnation -> ids
    std::set<std::uint32_t> fast_seen;
    for (const auto& d : rx.received) {
        require(d.bytes.size() >= 4);
        const std::uint32_t id = test::id_of(d.bytes);
        // Ids are unique across incarnations: the top byte says which.
        const std::size_t inc = id >> 24;
        require(inc < senders.size());
        const auto it = senders[inc].sent.find(id);
        require(it != senders[inc].sent.end());
        require(it->second == d.bytes);
        if (d.cls == MessageClass::Safe) {
            require(d.priority < 4);
            safe_got[d.priority][inc].push_back(id);
        } else {
            require(fast_seen.insert(id).second);
        }
    }
    for (std::size_t ch = 0; ch < 4; ++ch) {
        for (const auto& [inc, ids] : safe_got[ch]) {
            const auto& order = senders[inc].safe_order[ch];
            // In order and without duplicates: a subsequence of the send order that never goes back.
            std::size_t cursor = 0;
            for (std::uint32_t id : ids) {
                while (cursor < order.size() && order[cursor] != id) {
                    ++cursor;
                }
                require(cursor < order.size());
                ++cursor;
            }
        }
    }
}

std::size_t pending(const test::Endpoint& e) {
    std::size_t n = 0;
    for (std::uint8_t ch = 0; ch < 4; ++ch) {
        n += e.core->safe_pending(ch);
    }
    return n;
}

void run_scenario(Script& s) {
    test::PathModel pm;
    pm.rate = 2000.0 + 100.0 * s.byte();
    pm.imp.loss = s.fraction(0.4);
    pm.imp.byte_corrupt = s.fraction(2e-3);
    pm.imp.duplicate = s.fraction(0.2);
    pm.imp.reorder = s.fraction(0.3);
    pm.imp.garbage = s.fraction(0.1);
    std::uint64_t nonce = 100;
    auto config = [&] {
        TransportConfig c = test::base_config(++nonce, true);
        c.link_rate_bytes_per_s = pm.rate;
        return c;
    };
    test::SimLink link(config(), config(), {pm}, s.u32());
    // Per end: the incarnations that have sent (index = incarnation number, part of each message id).
    std::array<std::vector<Incarnation>, 2> incarnations{std::vector<Incarnation>(1),
                                                         std::vector<Incarnation>(1)};
    std::array<std::uint32_t, 2> next_id{1, 1};

    for (int step = 0; step < 64 && !s.done(); ++step) {
        const std::uint8_t op = s.byte();
        const int end = op & 1;
        switch ((op >> 1) % 6) {
            case 0:
            case 1: {  // traffic from `end`
                const int n = 1 + s.byte() % 4;
                for (int k = 0; k < n; ++k) {
                    auto& inc = incarnations[static_cast<std::size_t>(end)].back();
                    const auto number =
                        static_cast<std::uint32_t>(incarnations[static_cast<std::size_t>(end)].size() - 1);
                    const std::uint32_t id =
                        (number << 24) | (next_id[static_cast<std::size_t>(end)]++ & 0xFFFFFFU);
                    const std::uint8_t shape = s.byte();
                    const auto prio = static_cast<std::uint8_t>(shape & 3);
                    const std::size_t size = 4 + (shape & 0x80 ? 4u * s.byte() * 4u : s.byte());
                    auto msg = test::pattern(size, id);
                    inc.sent[id] = msg;
                    if (shape & 0x40) {
                        link.end(end).core->send_fast(prio, static_cast<std::uint16_t>(shape >> 2 & 7), msg,
                                                      link.now());
                    } else if (link.end(end).core->send_safe(prio, msg, link.now()) == SendResult::Accepted) {
                        inc.safe_order[prio].push_back(id);
                    }
                }
                break;
            }
            case 2:  // time passes
                link.run_for(std::chrono::milliseconds(50) * (1 + s.byte()));
                break;
            case 3: {  // an outage of one direction or both, up to ~90 s
                const int which = s.byte() % 3;
                auto& p = link.path(0);
                p.a_to_b_up = which == 1;
                p.b_to_a_up = which == 0;
                link.run_for(std::chrono::milliseconds(350) * (1 + s.byte()));
                p.a_to_b_up = p.b_to_a_up = true;
                break;
            }
            case 4: {  // `end` restarts: a new process, new nonce, nothing kept
                link.restart(end, config());
                link.end(end).received.clear();
                incarnations[static_cast<std::size_t>(end)].emplace_back();
                require(incarnations[static_cast<std::size_t>(end)].size() < 256);
                break;
            }
            case 5: {  // someone else on the frequency: replays and noise
                const auto& rec = link.recorded(1 - end);
                if (!rec.empty()) {
                    link.inject(end, 0, rec[s.u32() % rec.size()]);
                }
                std::vector<std::uint8_t> junk(s.byte() % 64);
                for (auto& b : junk) {
                    b = s.byte();
                }
                link.inject(end, 0, junk);
                break;
            }
        }
        require(!link.livelocked());
    }
    check_received(link.b(), incarnations[0]);
    check_received(link.a(), incarnations[1]);

    link.path(0).imp = test::Impairments{};
    const TimePoint give_up = link.now() + 200s;
    link.run_until(give_up, [&] {
        return pending(link.a()) == 0 && pending(link.b()) == 0 && link.a().core->session_established() &&
               link.b().core->session_established();
    });
    require(!link.livelocked());
    if (pending(link.a()) != 0 || pending(link.b()) != 0 || !link.a().core->session_established() ||
        !link.b().core->session_established()) {
        std::fprintf(stderr,
                     "after 200 s of clean link: a pending %zu session %d, b pending %zu session %d\n",
                     pending(link.a()), int(link.a().core->session_established()), pending(link.b()),
                     int(link.b().core->session_established()));
        for (const auto* e : {&link.a(), &link.b()}) {
            const auto& st = e->core->stats();
            std::fprintf(
                stderr,
                "  %s: frames sent %llu recv %llu replays %llu mac %llu crc %llu restarts %llu acks "
                "sent %llu recv %llu safe_resent %llu refused %llu tx.safe msgs %llu retx %llu rx.safe "
                "msgs %llu; pending per channel %zu %zu %zu %zu\n",
                e == &link.a() ? "a" : "b", (unsigned long long)st.frames_sent,
                (unsigned long long)st.frames_received, (unsigned long long)st.replays,
                (unsigned long long)st.mac_failures, (unsigned long long)st.crc_errors,
                (unsigned long long)st.peer_restarts, (unsigned long long)st.acks_sent,
                (unsigned long long)st.acks_received, (unsigned long long)st.safe_resent,
                (unsigned long long)st.deliveries_refused, (unsigned long long)st.tx_safe.messages,
                (unsigned long long)st.tx_safe.retransmissions, (unsigned long long)st.rx_safe.messages,
                e->core->safe_pending(0), e->core->safe_pending(1), e->core->safe_pending(2),
                e->core->safe_pending(3));
        }
    }
    require(pending(link.a()) == 0 && pending(link.b()) == 0);
    require(link.a().core->session_established() && link.b().core->session_established());
    check_received(link.b(), incarnations[0]);
    check_received(link.a(), incarnations[1]);
}

void run_raw(std::span<const std::uint8_t> bytes) {
    TimePoint now = TimePoint{} + 1h;
    Transport keyed(test::base_config(7, true), now);
    Transport open(test::base_config(8, false), now);
    std::size_t pos = 0;
    while (pos < bytes.size()) {
        const std::size_t n = std::min<std::size_t>(bytes.size() - pos, 1 + (bytes[pos] % 97));
        const auto chunk = bytes.subspan(pos, n);
        keyed.handle_bytes(0, chunk, now);
        open.handle_bytes(0, chunk, now);
        pos += n;
        now += std::chrono::milliseconds(bytes[pos - 1] % 200);
        keyed.handle_timeout(now);
        open.handle_timeout(now);
        while (keyed.poll_transmit(0, now) || open.poll_transmit(0, now)) {
        }
        require(!keyed.poll_message().has_value());
        while (open.poll_message()) {
        }
        while (keyed.poll_event() || open.poll_event()) {
        }
    }
    // Nothing authenticates without the key: not a frame, not a hello.
    require(keyed.stats().frames_received == 0);
    require(!keyed.session_established());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) {
        return 0;
    }
    const std::span<const std::uint8_t> input(data, size);
    Script s(input.subspan(1));
    if (input[0] & 1) {
        run_raw(input.subspan(1));
    } else {
        run_scenario(s);
    }
    return 0;
}
