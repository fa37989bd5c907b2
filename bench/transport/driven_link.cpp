#include "bench/transport/driven_link.hpp"

#include <valgrind/callgrind.h>

#include <algorithm>
#include <stdexcept>

namespace airseg::transport_bench {
namespace {

// The radios add this to every byte's trip (serial buffers, air packet assembly).
constexpr auto kRadioLatency = std::chrono::milliseconds(5);

}  // namespace

DrivenLink::DrivenLink(const groundlink::TransportConfig& a, const groundlink::TransportConfig& b,
                       double air_rate, std::size_t read_bytes, Selection selection)
    : ends_{End{a, TimePoint{} + std::chrono::hours(1)}, End{b, TimePoint{} + std::chrono::hours(1)}},
      air_rate_(air_rate),
      read_bytes_(std::max<std::size_t>(read_bytes, 1)),
      selection_(selection),
      now_(TimePoint{} + std::chrono::hours(1)),
      air_free_(now_) {
    pump(0);
    pump(1);
}

bool DrivenLink::selected(int end, bool is_poll_transmit) const {
    switch (selection_) {
        case Selection::None:
            return false;
        case Selection::EndA:
            return end == 0;
        case Selection::EndB:
            return end == 1;
        case Selection::Both:
            return true;
        case Selection::PollTransmit:
            return is_poll_transmit;
    }
    return false;
}

// Counts the instructions of `call` alone when the selection asks for it (a no-op outside valgrind).
#define AIRSEG_METERED(end, is_poll_transmit, call)            \
    [&] {                                                      \
        const bool metered_ = selected(end, is_poll_transmit); \
        if (metered_) {                                        \
            CALLGRIND_TOGGLE_COLLECT;                          \
        }                                                      \
        auto result_ = call;                                   \
        if (metered_) {                                        \
            CALLGRIND_TOGGLE_COLLECT;                          \
        }                                                      \
        return result_;                                        \
    }()

groundlink::SendResult DrivenLink::send_safe(int end, std::uint8_t priority,
                                             std::span<const std::uint8_t> msg) {
    End& e = ends_[idx(end)];
    e.tally.calls.sends += counting_ ? 1 : 0;
    const auto r = AIRSEG_METERED(end, false, e.core.send_safe(priority, msg, now_));
    pump(end);
    return r;
}

groundlink::SendResult DrivenLink::send_fast(int end, std::uint8_t priority, std::uint16_t topic,
                                             std::span<const std::uint8_t> msg) {
    End& e = ends_[idx(end)];
    e.tally.calls.sends += counting_ ? 1 : 0;
    const auto r = AIRSEG_METERED(end, false, e.core.send_fast(priority, topic, msg, now_));
    pump(end);
    return r;
}

void DrivenLink::pump(int end) {
    End& e = ends_[idx(end)];
    // As LinkDriver: a handler that sends pumps again; finish this round first, then loop.
    if (e.pumping) {
        e.pump_again = true;
        return;
    }
    e.pumping = true;
    do {
        e.pump_again = false;
        e.tally.calls.pumps += counting_ ? 1 : 0;
        for (std::size_t p = 0; p < e.core.config().paths; ++p) {
            while (true) {
                auto frame = AIRSEG_METERED(end, true, e.core.poll_transmit(p, now_));
                e.tally.calls.poll_transmit += counting_ ? 1 : 0;
                if (!frame) {
                    break;
                }
                e.tally.calls.frames += counting_ ? 1 : 0;
                e.tally.wire_bytes += counting_ ? frame->size() : 0;
                for (const std::uint8_t byte : *frame) {
                    e.tally.wire_digest = (e.tally.wire_digest ^ byte) * 0x100000001b3ULL;
                }
                write(end, std::move(*frame));
            }
        }
        while (true) {
            auto m = AIRSEG_METERED(end, false, e.core.poll_message());
            if (!m) {
                break;
            }
            if (counting_) {
                ++e.tally.delivered_messages;
                e.tally.delivered_bytes += m->bytes.size();
            }
            if (on_message_) {
                on_message_(end, *m);
            }
        }
        while (AIRSEG_METERED(end, false, e.core.poll_event())) {
        }
    } while (e.pump_again);
    e.pumping = false;
    e.armed = AIRSEG_METERED(end, false, e.core.poll_timeout());
}

void DrivenLink::write(int from, std::vector<std::uint8_t> frame) {
    // Half duplex: the frame waits for the pair's air, then its bytes come off the air at air_rate and the
    // receiving UART hands them over read_bytes at a time.
    const TimePoint start = std::max(now_, air_free_);
    const auto byte_time = std::chrono::duration<double>(1.0 / air_rate_);
    for (std::size_t off = 0; off < frame.size(); off += read_bytes_) {
        const std::size_t n = std::min(read_bytes_, frame.size() - off);
        const auto at = start +
                        std::chrono::duration_cast<Duration>(byte_time * static_cast<double>(off + n)) +
                        kRadioLatency;
        const auto first = frame.begin() + static_cast<std::ptrdiff_t>(off);
        reads_.emplace(
            at, Read{1 - from, std::vector<std::uint8_t>(first, first + static_cast<std::ptrdiff_t>(n))});
    }
    air_free_ = start + std::chrono::duration_cast<Duration>(byte_time * static_cast<double>(frame.size()));
}

void DrivenLink::run_until(TimePoint until) {
    std::size_t idle_steps = 0;  // inputs handled without the clock moving
    TimePoint last = now_;
    while (true) {
        if (now_ != last) {
            last = now_;
            idle_steps = 0;
        } else if (++idle_steps > 100000) {
            throw std::runtime_error("transport bench: livelock (a deadline in the past never clears)");
        }
        TimePoint next = until;
        if (!reads_.empty()) {
            next = std::min(next, reads_.begin()->first);
        }
        for (const End& e : ends_) {
            next = std::min(next, e.armed);
        }
        if (next >= until && (reads_.empty() || reads_.begin()->first > until) &&
            std::all_of(ends_.begin(), ends_.end(), [&](const End& e) { return e.armed > until; })) {
            now_ = std::max(now_, until);
            return;
        }
        now_ = std::max(now_, next);
        if (!reads_.empty() && reads_.begin()->first <= now_) {
            auto node = reads_.extract(reads_.begin());
            Read& r = node.mapped();
            End& e = ends_[idx(r.to)];
            e.tally.calls.handle_bytes += counting_ ? 1 : 0;
            AIRSEG_METERED(r.to, false, (e.core.handle_bytes(0, r.bytes, now_), 0));
            pump(r.to);
            continue;
        }
        for (int end = 0; end < 2; ++end) {
            End& e = ends_[idx(end)];
            if (e.armed <= now_) {
                e.armed = kNever;
                e.tally.calls.handle_timeout += counting_ ? 1 : 0;
                AIRSEG_METERED(end, false, (e.core.handle_timeout(now_), 0));
                pump(end);
            }
        }
    }
}

}  // namespace airseg::transport_bench
