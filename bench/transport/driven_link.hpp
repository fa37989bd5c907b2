#pragma once
// Two ground-link Transport cores driven the way airsegd's LinkDriver drives one (services/groundlink/link/
// link_driver.cpp), in simulated time: after every input (a serial read, an application send, the timer)
// the end is pumped: poll_transmit until nullopt on each path, every frame written at once, then
// poll_message and poll_event drained and one timer re-armed at poll_timeout(). The ends are joined by one
// half-duplex radio pair (both directions share its air time) that hands the receiver its bytes in UART
// reads of `read_bytes`, as they come off the air.
//
// Every call into a core goes through Meter, so a callgrind run can count the instructions of exactly the
// calls it selects (CALLGRIND_TOGGLE_COLLECT around each; see bench/transport/callgrind.sh).
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <vector>

#include "services/groundlink/transport/transport.hpp"

namespace airseg::transport_bench {

/// Which transport calls a callgrind run counts.
enum class Selection : std::uint8_t { None, EndA, EndB, Both, PollTransmit };

struct CallCounts {
    std::uint64_t poll_transmit = 0;
    std::uint64_t frames = 0;  ///< poll_transmit calls that returned a frame
    std::uint64_t handle_bytes = 0;
    std::uint64_t handle_timeout = 0;
    std::uint64_t sends = 0;
    std::uint64_t pumps = 0;
};

struct EndTally {
    CallCounts calls;
    std::uint64_t delivered_messages = 0;
    std::uint64_t delivered_bytes = 0;  ///< payload bytes delivered to this end's application
    std::uint64_t wire_bytes = 0;       ///< bytes this end wrote
    /// FNV-1a over every frame this end wrote, all run long: equal digests, equal behaviour on the wire.
    std::uint64_t wire_digest = 0xcbf29ce484222325ULL;
};

class DrivenLink {
  public:
    using OnMessage = std::function<void(int end, const groundlink::Delivered&)>;

    DrivenLink(const groundlink::TransportConfig& a, const groundlink::TransportConfig& b, double air_rate,
               std::size_t read_bytes, Selection selection);

    [[nodiscard]] TimePoint now() const { return now_; }
    [[nodiscard]] const groundlink::Transport& core(int end) const { return ends_[idx(end)].core; }
    /// Tallies count only while `counting` is set (the measured window).
    void set_counting(bool on) { counting_ = on; }
    [[nodiscard]] const EndTally& tally(int end) const { return ends_[idx(end)].tally; }
    void on_message(OnMessage f) { on_message_ = std::move(f); }

    groundlink::SendResult send_safe(int end, std::uint8_t priority, std::span<const std::uint8_t> msg);
    groundlink::SendResult send_fast(int end, std::uint8_t priority, std::uint16_t topic,
                                     std::span<const std::uint8_t> msg);

    /// Runs every input due up to `until`, in time order (each followed by a pump), then sets the clock
    /// there.
    void run_until(TimePoint until);

  private:
    struct End {
        End(const groundlink::TransportConfig& c, TimePoint now) : core(c, now) {}
        groundlink::Transport core;
        TimePoint armed = kNever;
        EndTally tally;
        bool pumping = false;
        bool pump_again = false;
    };
    struct Read {
        int to = 0;
        std::vector<std::uint8_t> bytes;
    };

    static std::size_t idx(int end) { return static_cast<std::size_t>(end); }
    [[nodiscard]] bool selected(int end, bool is_poll_transmit) const;
    void pump(int end);
    void write(int from, std::vector<std::uint8_t> frame);

    std::array<End, 2> ends_;
    double air_rate_;
    std::size_t read_bytes_;
    Selection selection_;
    TimePoint now_;
    TimePoint air_free_;
    std::multimap<TimePoint, Read> reads_;
    bool counting_ = false;
    OnMessage on_message_;
};

}  // namespace airseg::transport_bench
