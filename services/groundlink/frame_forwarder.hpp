#pragma once
// FrameForwarder: decides which of the autopilot's frames go to the ground for standard ground stations, and
// when. Sans-IO: frames and time in, frames to send out.
//
// Contract: the caller passes `now` to every call and never lets it go backwards.
//   inputs   offer(frame, now) for each autopilot::ForwardedFrame, link up or down; link_down() when the
//            link goes down (freshest frames waiting would be stale when it comes back; reliable ones stay
//            queued and go once it is up again); put_back(out) for a reliable frame the transport could not
//            take yet.
//   outputs  poll(now): one frame to send now, or nothing (call until nothing, and only while the link is
//            up); poll_timeout(): when the next one may be due; stats().
//
// Freshest frames are rate-limited per message id: at most rate_hz of an id per second, and a newer frame of
// an id replaces one not yet sent (counted as replaced). Reliable frames (parameters, command and mission
// answers, status texts) queue in order, through a link outage too (beyond reliable_queue_bytes a new one is
// dropped and counted as overflow). Everything sent shares one byte budget (a token
// bucket with budget_bytes_per_s, at most burst_s of it saved up): when it is spent, nothing goes until it
// refills, so airseg's own telemetry keeps its share of the link. While both kinds wait, they take turns.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "base/time.hpp"
#include "services/autopilot/autopilot.hpp"

namespace airseg::groundlink {

struct FrameForwarderConfig {
    /// groundlink.mavlink_forward.enabled
    bool enabled = false;
    /// groundlink.mavlink_forward.budget_bytes_per_s; 0 = default_budget_share of the link rate.
    double budget_bytes_per_s = 0.0;
    static constexpr double kDefaultBudgetShare = 0.3;
    /// groundlink.mavlink_forward.rates: Hz per message id for freshest frames (0 = never forwarded).
    std::map<std::uint32_t, double> rate_hz;
    /// Hz of a freshest message id without an entry in rate_hz.
    double default_hz = 1.0;
    /// Bytes the transport adds to each forwarded message (chunk header, the frame's share of framing).
    double overhead_bytes = 8.0;
    /// Reliable frames waiting, at most this many bytes. A full parameter download of ArduPilot Rover (about
    /// 280 PARAM_VALUE frames of 37 bytes at most, 10.4 kB) fits three times, with the mission's answers
    /// and status texts beside it, through an outage of the radio.
    std::size_t reliable_queue_bytes = 32 * 1024;
    /// Budget saved up while idle, in seconds of budget.
    double burst_s = 0.5;

    /// Every problem, each naming its key; empty when usable.
    [[nodiscard]] std::vector<std::string> validate() const;
};

/// One freshest message id's counts: whether its rate fell short at the ground because the forwarder held it
/// back (a long gap here) or because it was lost after it.
struct FreshestIdStats {
    std::uint64_t offered = 0;
    std::uint64_t forwarded = 0;
    std::uint64_t replaced = 0;
    std::uint64_t stale = 0;
    Duration longest_gap{};  // between two frames of the id handed out, since the first
};

struct FrameForwarderStats {
    std::uint64_t offered = 0;
    std::uint64_t forwarded = 0;  // frames handed out by poll()
    std::uint64_t forwarded_bytes = 0;
    std::uint64_t replaced = 0;  // freshest frames replaced by a newer one of their id before going out
    std::uint64_t filtered = 0;  // freshest frames of an id whose rate is 0
    std::uint64_t dropped = 0;   // reliable frames refused by a full queue (overflow), or cleared by clear()
    std::uint64_t stale = 0;     // freshest frames waiting when the link went down, dropped by link_down()
    std::size_t reliable_queued = 0;        // reliable frames waiting now
    std::size_t reliable_queued_bytes = 0;  // ... their bytes
    /// Per freshest id offered (bounded by the dialect: only verified frames of known ids are offered).
    std::map<std::uint32_t, FreshestIdStats> freshest_by_id;
};

class FrameForwarder {
  public:
    /// `link_rate_bytes_per_s` gives the budget when the configuration leaves it at 0.
    FrameForwarder(FrameForwarderConfig config, double link_rate_bytes_per_s, TimePoint now);

    void offer(const autopilot::ForwardedFrame& frame, TimePoint now);
    /// The link went down: freshest frames waiting are dropped (counted as stale); reliable ones stay.
    void link_down();
    /// Drops everything waiting (counted as dropped).
    void clear();

    struct Out {
        autopilot::ForwardedFrame::Delivery delivery = autopilot::ForwardedFrame::Delivery::Freshest;
        std::uint32_t id = 0;
        std::vector<std::uint8_t> bytes;
    };
    std::optional<Out> poll(TimePoint now);
    /// A reliable frame poll() gave out and the transport refused (its queue full): first again, its bytes
    /// given back to the budget. Freshest frames are not put back (a newer one will come).
    void put_back(Out out);
    [[nodiscard]] TimePoint poll_timeout() const;

    [[nodiscard]] FrameForwarderStats stats() const;
    [[nodiscard]] double budget_bytes_per_s() const { return budget_; }
    [[nodiscard]] const FrameForwarderConfig& config() const { return config_; }

  private:
    struct Slot {
        std::vector<std::uint8_t> bytes;
        bool pending = false;
        TimePoint next_allowed{};  // the id's rate limit: the earliest moment its next frame may go
        Duration interval{};
        TimePoint last_forwarded{};  // TimePoint{} until the first
        FreshestIdStats stats;
    };
    void refill(TimePoint now);
    [[nodiscard]] double rate_of(std::uint32_t id) const;
    /// The freshest slot that may go now (the one allowed longest ago), or end().
    std::map<std::uint32_t, Slot>::iterator due_slot(TimePoint now);
    Out take(Out out);

    FrameForwarderConfig config_;
    double budget_;  // bytes per second
    double tokens_;  // bytes that may go now; negative after a frame larger than what was saved
    TimePoint refilled_at_;
    std::map<std::uint32_t, Slot> slots_;
    std::deque<Out> reliable_;
    std::size_t reliable_bytes_ = 0;
    bool reliable_turn_ = true;
    FrameForwarderStats stats_;
};

}  // namespace airseg::groundlink
