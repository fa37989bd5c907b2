#pragma once
// WindowFeeder: keeps a rolling window of plan waypoints on the autopilot so that it never reaches the end
// of its mission while the plan has more (the circular waypoint queue of APM:Rover navigation, made
// robust). Sans-IO: no autopilot protocol, no clock, no thread.
//
// Mission layout (see docs/flight-plan.md): slot 0 home (the driver's), slot 1 where a board that restarts
// its mission on entering AUTO begins (a waypoint the driver points it on from at once), then a ring of K
// positions: slots 2..K, and the wrap W = slots K+1..K+3, written together as [wp, JumpTo(2), wp]. From
// W's waypoint the jump takes the vehicle on to slot 2 (both ways ArduPilot has run a DO_JUMP find the
// waypoint after it); K+3 is never driven. Reports of slots K+2..K+3 count as W.
//
// The safety invariant: every slot the autopilot can reach without another write from here holds either
// the plan's entry for that position or a Stop at the point of the entry before it (the barrier). The
// window holds up to K-1 entries from the head in ring order, and the slot after the last holds its
// barrier; a slot is written with an entry only once the slot after it holds that entry's barrier, so a
// vehicle whose feeder fell behind stops at the frontier and waits (HeldAtFrontier) instead of driving a
// slot left from an earlier round. A hold's waypoint (a timed hold, one until released, or the point a hold
// without a position is held at) is the last entry of the window until the vehicle has reached it: its
// barrier stops the vehicle there even when this daemon does not run, and what follows is written once the
// hold has begun. The writes after a reached waypoint land three or more waypoints ahead
// of the vehicle's target, outside the look-ahead of ArduPilot's mission change detector (the current
// navigation command and the next two), so they never restart the leg being driven.
//
// Contract (the driver, on the service's strand):
//   inputs   replace_plan(), skip_to(), jump_to(), pause(), resume(), release_hold(),
//            on_reached(slot), on_current(slot), on_item_stored(slot, item), on_mode(state, cause),
//            on_request_result(id, result),
//            on_autopilot_rebooted(), set_stop_ends_mission(ends) (with a write's result),
//            handle_timeout(now) when poll_timeout() is due;
//   outputs  poll_request(now) after every input, until it returns nothing: at most one request is
//            outstanding; each ends with exactly one on_request_result() (or a timeout);
//            poll_event() until empty; progress() any time.
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/time.hpp"
#include "services/flightplan/feeder_types.hpp"
#include "services/flightplan/waypoint.hpp"

namespace airseg::flightplan {

struct FeederConfig {
    std::uint16_t window = 5;                  // flightplan.window: K ring slots (>= 3)
    std::uint32_t retries = 3;                 // flightplan.retries: extra attempts per request
    Duration request_timeout = seconds(5);     // flightplan.request_timeout
    Duration fault_backoff = seconds(5);       // pause before trying again after a request failed for good
    std::uint32_t lost_reached_tolerance = 1;  // reached/current reports may skip this many entries
    bool resume_after_reboot = true;           // flightplan.resume_after_reboot
    /// Empty when valid, else what is wrong.
    std::optional<std::string> validate() const;
};

struct PlanFeed {
    std::unique_ptr<WaypointStream> stream;
    std::string name;
};

class WindowFeeder {
  public:
    explicit WindowFeeder(FeederConfig config = {});

    /// Start a plan, or replace the running one. The autopilot's current target is kept (the vehicle
    /// carries on to it, then heads to the new plan's first waypoint without stopping); nothing is
    /// cleared. A paused feeder stays paused.
    void replace_plan(PlanFeed feed, TimePoint now);
    /// Head for expanded waypoint `index` now. False (and nothing changes) if the stream has no such index.
    bool skip_to(std::uint64_t index, TimePoint now);
    /// Continue at the named element now (a reaction's lost-link path). False if there is no such element.
    bool jump_to(std::string_view element_name, TimePoint now);
    /// Resume a stream restored from persistence: like replace_plan, with the reached count carried over.
    void restore_plan(PlanFeed feed, std::uint64_t waypoints_reached, TimePoint now);
    /// Swap the stream for one that continues it (the same plan with elements appended): from its current
    /// position `feed.stream` must produce what the current stream would produce next. Nothing already on
    /// the autopilot changes and the counts stay; if the current stream had ended, its Stop item gives way
    /// to what follows (a finished plan starts again at the first appended waypoint).
    void continue_with(PlanFeed feed, TimePoint now);
    /// Forget the plan: no more requests; the vehicle finishes its current target and then holds.
    void clear_plan();
    void pause();
    void resume();
    /// Ends a hold-until-released (or a timed hold early).
    void release_hold(TimePoint now);

    void on_reached(std::uint16_t slot, TimePoint now);
    void on_current(std::uint16_t slot, TimePoint now);
    /// An item of the write in flight is on the board already (the board asked for the next one), told in
    /// order with its reports: the slot is confirmed from here on, before the write's result.
    void on_item_stored(std::uint16_t slot, const autopilot::MissionItem& item);
    /// The vehicle's state changed (`cause` Requested: by this daemon, the feeder or an operator's state
    /// command). Leaving AUTO while the plan runs, without the feeder asking, interrupts it: the board's own
    /// HOLD (end of its mission, a quirk, a failsafe) is undone at once (the window is made whole, the head
    /// set current, AUTO asked for); a vehicle taken by hand (the RC pilot, or an operator's state command to
    /// a manual state) is left to whoever took it until resume(); an operator's state command to HOLD pauses
    /// the plan.
    void on_mode(autopilot::VehicleState state, autopilot::ModeChangeCause cause, TimePoint now);
    /// `detail` is the autopilot's answer, for a refusal: a refused mission write fails the plan.
    void on_request_result(std::uint32_t id, autopilot::RequestResult result, TimePoint now,
                           std::string_view detail = {});
    void on_autopilot_rebooted(TimePoint now);
    /// How the board runs a Stop, as its last mission write said: as the end of its mission, holding there
    /// in HOLD (APM:Rover 2.x), or staying in AUTO (current Rover). Until told, a HOLD where a 2.x board
    /// would hold by itself is taken for that board's.
    void set_stop_ends_mission(bool ends) {
        stop_ends_mission_ = ends;
        stop_kind_told_ = true;
    }
    void handle_timeout(TimePoint now);

    std::optional<FeederRequest> poll_request(TimePoint now);
    TimePoint poll_timeout() const;
    std::optional<FeederEvent> poll_event();
    FeederProgress progress() const;
    const FeederConfig& config() const { return config_; }

  private:
    struct Entry {
        Waypoint wp;
        bool stop = false;
        std::vector<Waypoint> holds_after;  // holds without a position, held when wp is reached
        std::uint16_t slot = 1;
        std::uint32_t generation = 0;
        std::string element_path;
        bool announced = false;  // ElementStarted considered (once, when it became the head)
        /// The plan holds the vehicle at this entry's point: nothing after it is written before it is
        /// reached.
        bool holds_vehicle() const { return wp.action != WaypointAction::Go || !holds_after.empty(); }
        autopilot::MissionItem item() const;
        /// The Stop that ends the drivable part of the ring after this entry: at its point.
        autopilot::MissionItem barrier() const;
    };
    struct Outstanding {
        FeederRequest request;
        TimePoint deadline;
        bool read_grace = false;  // the deadline was already put off once for a late wake
    };
    /// How far the vehicle can drive on what the autopilot holds, from the head: `entries` queue entries on
    /// board in ring order, then either their barrier (or a Stop entry) ends it, or a slot holding anything
    /// else — content the vehicle must never reach — breaks it at `entries`.
    struct Chain {
        std::size_t entries = 0;
        bool broken = false;
    };
    enum class Mode : std::uint8_t { Unknown, Auto, Hold, Manual };

    static constexpr std::uint16_t kFirstRingSlot = 2;
    /// A request overdue by more than this when the feeder wakes was not answered because the daemon was not
    /// running: it is given kReadGrace for the answers waiting in the port before it is asked again.
    static constexpr Duration kLateWake = milliseconds(250);
    static constexpr Duration kReadGrace = milliseconds(250);
    static constexpr std::uint16_t kWrapSlots = 3;
    /// W, the last ring position: slots K+1..K+3.
    std::uint16_t wrap_slot() const { return static_cast<std::uint16_t>(config_.window + 1); }
    std::uint16_t ring_next(std::uint16_t slot) const {
        return slot >= wrap_slot() ? kFirstRingSlot : slot + 1;
    }
    /// A slot the autopilot reports, as a ring position (the wrap's slots are W).
    std::uint16_t ring_position(std::uint16_t slot) const {
        return slot > wrap_slot() && slot < wrap_slot() + kWrapSlots ? wrap_slot() : slot;
    }
    /// What a ring position holds on board for `item`: the item, or at W the whole wrap.
    std::vector<autopilot::MissionItem> slot_items(std::uint16_t slot,
                                                   const autopilot::MissionItem& item) const;
    bool confirmed(const Entry& e) const;
    /// The autopilot is known to hold `item` at ring position `slot`.
    bool holds(std::uint16_t slot, const autopilot::MissionItem& item) const;
    /// The autopilot is known to hold a Stop at ring position `slot` (a barrier, or the plan's end).
    /// The slot of `e` holds e's item: what the vehicle drives to there is the entry (the wrap's jump and
    /// copy after it aside, which `confirmed` also checks).
    bool drives_to(const Entry& e) const;
    bool holds_stop(std::uint16_t slot) const;
    Chain chain_from(std::size_t first) const;
    /// Entries the window keeps: K-1, one less while the vehicle still heads for a slot outside it (the
    /// slot after the last entry must stay writable for its barrier).
    std::size_t capacity() const;
    void start_fresh(TimePoint now);
    void restart(TimePoint now);
    void refill(TimePoint now);
    void complete_through(std::size_t position, TimePoint now);
    void begin_hold(TimePoint now);
    void end_hold(TimePoint now);
    void check_done();
    void announce_head();
    std::string stream_path(const Waypoint& wp) const;
    void request_failed(TimePoint now);
    void check_starvation();
    /// The vehicle stands at a barrier: the head's slot holds a Stop, and the board reports being there.
    void at_frontier(TimePoint now);
    /// Counts and reports a stop at the frontier (not one at a hold's barrier, where the plan stops anyway).
    void count_frontier_stop();
    void left_frontier(TimePoint now);
    bool plan_active() const;
    void interrupt(std::string why, bool wait_for_operator);
    void fail_plan(std::string why);
    void emit(FeederEvent::Kind kind, const Waypoint* wp, std::uint32_t generation, std::string path = {},
              std::string detail = {});
    std::optional<Mode> desired_mode() const;
    bool ready_for_auto() const;
    /// The next write that brings the ring closer to the window without ever breaking the invariant.
    std::optional<FeederRequest> next_write(TimePoint now);
    std::optional<FeederRequest> write(std::uint16_t slot, const autopilot::MissionItem& item, TimePoint now);
    FeederRequest issue(decltype(FeederRequest::op) op, TimePoint now);
    void request_succeeded(const FeederRequest& request, TimePoint now);

    FeederConfig config_;
    std::unique_ptr<WaypointStream> stream_;
    std::string plan_name_;
    std::uint32_t generation_ = 0;
    std::uint32_t extensions_ = 0;  // continue_with() calls since the plan was loaded
    bool stream_ended_ = false;
    std::deque<Entry> queue_;            // queue_[0] is the current target
    std::optional<Waypoint> held_back_;  // taken from the stream, kept out while the last entry is a hold's
    std::uint16_t fresh_slot_ = kFirstRingSlot;  // slot of the first entry when the queue starts empty
    bool done_ = false;
    bool cleared_ = false;

    // What the autopilot is known to hold.
    bool mission_ok_ = false;
    std::vector<std::optional<autopilot::MissionItem>> confirmed_;  // by slot, 0..K+3
    // Slots where an entry replaced a barrier while the entry before it was not yet seen reached: a board
    // that got there first drives (or waits at) its copy of the Stop, whatever the slot holds now.
    std::vector<bool> written_over_stop_;
    // By slot: the items of the last write sent there, answered or not. A daemon stopped for seconds gives
    // up on answers still waiting in its port, so the board may hold these where confirmed_ says otherwise.
    std::vector<std::optional<autopilot::MissionItem>> sent_;
    std::optional<std::uint16_t> ap_target_;  // the slot the autopilot is believed to head for
    bool need_set_current_ = false;
    std::optional<std::uint16_t> old_target_;  // after a fresh start: the target the vehicle had, kept apart
    bool repoint_only_ =
        false;  // set-current due while the board's reports still count (its target is sound)
    Mode mode_ = Mode::Unknown;
    std::uint32_t current_mismatches_ = 0;

    bool paused_ = false;
    std::optional<std::string> interrupted_;  // why, while interrupted
    bool interrupted_by_hand_ = false;        // taken by hand: no AUTO until resume()
    std::string last_interruption_;
    std::optional<std::string> failed_;  // why the autopilot refused the plan
    bool starving_ = false;
    std::optional<TimePoint> frontier_since_;  // the vehicle waits at a barrier for the next write
    bool frontier_is_hold_ = false;            // ... where the plan holds it anyway: no frontier stop
    bool fault_ = false;
    TimePoint retry_not_before_ = TimePoint::min();
    std::uint32_t consecutive_failures_ = 0;
    bool fault_hold_pending_ = false;
    std::deque<Waypoint> holds_;  // holds to run, front first (the one being held while holding_)
    bool holding_ = false;
    bool stop_ends_mission_ = true;        // set_stop_ends_mission()
    bool stop_kind_told_ = false;          // ... was called
    std::optional<TimePoint> hold_until_;  // empty while holding: until released
    std::optional<Waypoint> hold_wp_;

    std::optional<Outstanding> outstanding_;
    std::uint32_t next_request_id_ = 1;
    std::deque<FeederEvent> events_;
    FeederProgress counters_;
    std::uint64_t reached_ = 0;
};

}  // namespace airseg::flightplan
