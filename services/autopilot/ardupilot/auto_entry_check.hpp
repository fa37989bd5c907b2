#pragma once
// AutoEntryCheck: makes every entry into AUTO continue at the mission slot the board was at, sans-IO.
//
// Some firmware (APM:Rover 2.x: set_mode(AUTO) runs restart_nav()) starts the mission again at item 1
// whenever AUTO is entered, whatever MISSION_SET_CURRENT said while the vehicle was held. The flight plan
// manager points the board at the right slot before it asks for AUTO; after the entry this check compares
// the board's MISSION_CURRENT with that slot and, when they differ, has the driver set it back. Until the
// board is back at the expected slot its MISSION_CURRENT is not reported onwards: the flight plan manager
// would take a jump to another slot of its ring for progress.
//
// The check is armed when AUTO is asked for or seen, and ends when the board reports the expected slot in
// AUTO, reaches it, is pointed elsewhere on purpose (retarget), leaves AUTO, or kWindow after the entry.
#include <cstdint>
#include <optional>

#include "base/time.hpp"

namespace airseg::autopilot::ardupilot {

class AutoEntryCheck {
  public:
    static constexpr Duration kWindow = seconds(3);
    /// Between two corrections: the answer to the first takes a round trip.
    static constexpr Duration kCorrectionGap = seconds(1);

    enum class Verdict : std::uint8_t {
        Report,    // pass the slot on
        Suppress,  // not the expected slot; a correction is on its way
        Correct,   // not the expected slot: set the current slot to expected() now
    };

    /// AUTO was asked for, or is seen without having been asked for; the board was at `expected`.
    void arm(std::uint16_t expected, TimePoint now);
    /// The board's heartbeat says AUTO.
    void on_auto(TimePoint now);
    /// The board left AUTO, or the link went down: nothing to check.
    void cancel() { expected_.reset(); }
    /// The current slot is being set to `slot` on purpose: that is the slot to expect.
    void retarget(std::uint16_t slot);
    void on_reached(std::uint16_t seq);
    Verdict on_current(std::uint16_t seq, TimePoint now);

    TimePoint poll_timeout() const { return expected_ ? deadline_ : kNever; }
    /// True when the check ended by running out of time (the caller reports the board's slot as it is).
    bool handle_timeout(TimePoint now);

    bool active() const { return expected_.has_value(); }
    std::optional<std::uint16_t> expected() const { return expected_; }
    /// Slots set back after an entry into AUTO, ever.
    unsigned corrections() const { return corrections_; }

  private:
    std::optional<std::uint16_t> expected_;
    bool in_auto_ = false;
    TimePoint deadline_ = kNever;
    std::optional<TimePoint> corrected_at_;
    unsigned corrections_ = 0;
};

}  // namespace airseg::autopilot::ardupilot
