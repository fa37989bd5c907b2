#pragma once
// What passes between standard ground stations (QGroundControl, Mission Planner, MAVProxy) and the autopilot,
// sans-IO: which autopilot frames must arrive at the ground (delivery_of), and which ground station frames
// may reach the autopilot (GcsGate).
//
// The flight plan manager owns the autopilot's mission: it feeds it a window at a time and must know every
// slot. A ground station writing the mission behind its back would break the plan, so mission writes
// (MISSION_COUNT, MISSION_ITEM(_INT), MISSION_CLEAR_ALL, MISSION_SET_CURRENT, MISSION_WRITE_PARTIAL_LIST for
// the mission itself; fences and rally points pass; MAV_CMD_DO_SET_MISSION_CURRENT in COMMAND_LONG or
// COMMAND_INT; and MAVFTP requests that create, open for writing, truncate, rename or remove a file of
// ArduPilot's @MISSION file system but for its fence.dat and rally.dat) never reach the autopilot: the gate
// answers the ground station itself, as the autopilot, with MISSION_ACK MAV_MISSION_DENIED (COMMAND_ACK
// MAV_RESULT_DENIED for the command, a MAVFTP NAK FileProtected for the file) and STATUSTEXTs saying why
// and what to do. With receive_uploads(), a mission upload goes to a MissionReceiver instead, which answers
// in the autopilot's name and hands the mission to the flight plan manager. Reading the mission, parameters
// (by message or MAVFTP), every other command (COMMAND_LONG and COMMAND_INT), TIMESYNC, position targets and
// everything else pass unchanged.
#include <cstdint>
#include <span>
#include <vector>

#include "base/time.hpp"
#include "services/autopilot/autopilot.hpp"
#include "services/autopilot/mavlink/encoder.hpp"
#include "services/autopilot/mavlink/frame.hpp"
#include "services/autopilot/mission_receiver.hpp"

namespace airseg::autopilot {

/// How a frame of this message id from the autopilot must travel to a ground station: Reliable for answers
/// a ground station waits for (parameter values, command and mission acknowledgements, mission items and
/// counts, texts), Freshest for telemetry.
ForwardedFrame::Delivery delivery_of(std::uint32_t msgid);

/// One whole frame from the autopilot as the bus carries it to ground stations.
ForwardedFrame forwarded(std::span<const std::uint8_t> frame);

/// The STATUSTEXT lines a refused mission write is answered with (each fits one STATUSTEXT).
std::span<const char* const> mission_refusal_texts();

struct GcsGateStats {
    std::uint64_t frames = 0;            // valid frames from ground stations
    std::uint64_t passed = 0;            // of those, written to the autopilot
    std::uint64_t missions_refused = 0;  // mission writes answered with a refusal (ftp_refused included)
    std::uint64_t ftp_refused = 0;       // of those, MAVFTP writes to @MISSION answered with a NAK
    std::uint64_t upload_frames = 0;     // mission upload frames handed to the MissionReceiver
    std::uint64_t invalid = 0;           // bytes that were no valid frame of a known message
};

class GcsGate {
  public:
    /// `autopilot_sysid/compid`: the autopilot's identity, which the answers carry.
    GcsGate(std::uint8_t autopilot_sysid, std::uint8_t autopilot_compid);

    struct Output {
        std::vector<std::vector<std::uint8_t>> to_autopilot;  // one frame each, in order
        std::vector<ForwardedFrame> to_ground;                // answers, one frame each
    };
    /// One or more whole frames from a ground station.
    Output from_ground(std::span<const std::uint8_t> frames, TimePoint now = {});

    /// Mission uploads (MISSION_COUNT and the items) go to `receiver` instead of being refused; the other
    /// mission writes stay refused. The receiver answers the ground station itself (its take_output()).
    void receive_uploads(MissionReceiver& receiver) { uploads_ = &receiver; }

    [[nodiscard]] const GcsGateStats& stats() const { return stats_; }

  private:
    bool refuse(const mavlink::Frame& f, Output& out);
    [[nodiscard]] bool addressed_to_autopilot(std::uint8_t target_system) const;

    std::uint8_t sysid_;
    mavlink::Encoder answers_;
    GcsGateStats stats_;
    MissionReceiver* uploads_ = nullptr;
};

}  // namespace airseg::autopilot
