#pragma once
// MissionReceiver: the vehicle side of the MAVLink mission upload, sans-IO, answering a standard ground
// station in the autopilot's name (as GcsGate does), so that a mission a ground station writes can become a
// flight plan instead of reaching the autopilot behind the flight plan manager's back.
//
// MISSION_COUNT (mission_type 0) starts an upload; each item is asked for with MISSION_REQUEST_INT, or with
// MISSION_REQUEST once the station answered with a float MISSION_ITEM. A request unanswered for
// `request_timeout` is sent again, up to `retries` times; then the upload ends with MISSION_ACK
// MAV_MISSION_OPERATION_CANCELLED, as ArduPilot does. Item 0 is home (ArduPilot's convention) and is skipped.
// Supported items: MAV_CMD_NAV_WAYPOINT (a waypoint), MAV_CMD_NAV_LOITER_TIME (a hold of param1 seconds
// there), MAV_CMD_NAV_LOITER_UNLIM (a stop until released), MAV_CMD_DO_CHANGE_SPEED (ignored: the plan sets
// its own speeds); frames global (0, 3, 5, 6) only. Anything else ends the upload at once with MISSION_ACK
// MAV_MISSION_UNSUPPORTED and STATUSTEXTs naming the item. A complete upload waits for a verdict (answer()):
// MISSION_ACK ACCEPTED, or DENIED with the reason as STATUSTEXTs of at most 50 characters each.
// While an upload or its verdict is pending, a MISSION_COUNT from another station is answered DENIED; the
// same station starting again restarts its upload.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/time.hpp"
#include "services/autopilot/autopilot.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/frame.hpp"

namespace airseg::autopilot {

struct MissionReceiverConfig {
    Duration request_timeout = milliseconds(1500);
    unsigned retries = 5;
};

/// A whole upload, in neutral terms: the items after home, in order.
struct ReceivedMission {
    std::uint8_t sysid = 0;  // the station that sent it
    std::uint8_t compid = 0;
    std::vector<MissionItem> items;  // Waypoint (hold_s set for a timed hold) or Stop
};

/// The STATUSTEXT lines for `reason`, split at spaces into pieces of at most 50 characters.
std::vector<std::string> statustext_lines(std::string_view reason);

class MissionReceiver {
  public:
    /// The most items an upload may announce (MISSION_COUNT, home included); a larger one is answered
    /// MAV_MISSION_NO_SPACE at once, so a station cannot make the vehicle hold 65,535 items.
    static constexpr std::uint16_t kMaxItems = 5000;
    /// STATUSTEXT lines a refusal is answered with, at most (a long reason is cut).
    static constexpr std::size_t kMaxTextLines = 8;

    MissionReceiver(std::uint8_t autopilot_sysid, std::uint8_t autopilot_compid,
                    MissionReceiverConfig config = {});

    /// A frame from a ground station. Returns true when it belonged to the upload protocol (MISSION_COUNT or
    /// MISSION_ITEM(_INT) addressed to the autopilot's mission), which must then not reach the autopilot.
    bool handle_frame(const mavlink::Frame& f, TimePoint now);
    void handle_timeout(TimePoint now);
    TimePoint poll_timeout() const;

    /// A complete upload awaiting its verdict (returned once).
    std::optional<ReceivedMission> poll_mission();
    /// The verdict on the upload poll_mission() returned: ACCEPTED, or DENIED with `reason`.
    void answer(bool accepted, std::string_view reason);

    /// Frames for the ground stations, oldest first.
    std::vector<ForwardedFrame> take_output();

    bool idle() const { return step_ == Step::Idle; }
    /// Uploads refused because they announced more than kMaxItems.
    std::uint64_t refused_too_large() const { return refused_too_large_; }

  private:
    enum class Step : std::uint8_t { Idle, Receiving, AwaitVerdict };

    void request(TimePoint now);
    void on_item(std::uint8_t sysid, std::uint8_t compid, const mavlink::MissionItemInt& item, bool as_int,
                 TimePoint now);
    void ack(std::uint8_t sysid, std::uint8_t compid, std::uint8_t type);
    void text(std::string_view reason);
    void end(std::uint8_t type, std::string_view reason);

    std::uint8_t sysid_;
    MissionReceiverConfig config_;
    mavlink::Encoder answers_;
    Step step_ = Step::Idle;
    std::uint8_t peer_sysid_ = 0;
    std::uint8_t peer_compid_ = 0;
    std::uint16_t count_ = 0;
    std::uint16_t next_ = 0;
    bool use_int_ = true;
    unsigned attempts_ = 0;
    TimePoint deadline_ = kNever;
    std::vector<MissionItem> items_;
    std::optional<ReceivedMission> complete_;
    std::vector<ForwardedFrame> out_;
    std::uint64_t refused_too_large_ = 0;
};

}  // namespace airseg::autopilot
