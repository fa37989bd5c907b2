#pragma once
// ReactionMonitor: decides when a plan's reactions fire. Sans-IO: link state, battery and position go in
// with the time; triggers come out. It only decides; carrying out the action (hold, return home, jump to a
// named block) is the caller's, through the WindowFeeder and the autopilot.
//
// Contract: call on_link / on_battery / on_position as data arrives, handle_timeout(now) when
// poll_timeout() is due, then poll_trigger() until empty.
//   link loss   fires once when the ground link has been down for `after` seconds without a break;
//               a "recovered" trigger follows when the link comes back.
//   low battery fires once when the level falls below `below` %; re-arms above below + hysteresis.
//   geofence    fires once when a position falls outside the fence; re-arms once the vehicle is back inside
//               by at least the hysteresis distance.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "base/time.hpp"
#include "services/flightplan/geo.hpp"
#include "services/flightplan/plan.hpp"

namespace airseg::flightplan {

struct ReactionSettings {
    std::optional<Reaction> link_loss;
    Duration link_loss_after = seconds(30);
    std::optional<Reaction> low_battery;
    double low_battery_percent = 20.0;
    double battery_hysteresis_percent = 5.0;
    std::optional<Reaction> geofence;
    LocalFrame frame;
    std::vector<Enu> fence;  // local polygon; empty = no fence
    double fence_hysteresis_m = 2.0;

    static ReactionSettings from_plan(const Plan& plan);
};

struct ReactionTrigger {
    enum class Cause : std::uint8_t { LinkLoss, LinkRecovered, LowBattery, Geofence };
    Cause cause = Cause::LinkLoss;
    Reaction reaction;  // what to do (for LinkRecovered: the link-loss reaction that is now over)
    TimePoint at{};
    std::string detail;
};
const char* to_string(ReactionTrigger::Cause cause);

class ReactionMonitor {
  public:
    explicit ReactionMonitor(ReactionSettings settings);

    void on_link(bool up, TimePoint now);
    void on_battery(double percent, TimePoint now);
    void on_position(LatLon position, TimePoint now);
    void handle_timeout(TimePoint now);

    TimePoint poll_timeout() const;
    std::optional<ReactionTrigger> poll_trigger();

    bool link_loss_active() const { return link_fired_; }
    std::uint64_t rejected_samples() const { return rejected_samples_; }

  private:
    void fire(ReactionTrigger::Cause cause, const Reaction& reaction, TimePoint now, std::string detail);

    ReactionSettings s_;
    std::optional<TimePoint> link_down_since_;
    bool link_fired_ = false;
    bool battery_fired_ = false;
    bool fence_fired_ = false;
    std::uint64_t rejected_samples_ = 0;
    std::deque<ReactionTrigger> triggers_;
};

}  // namespace airseg::flightplan
