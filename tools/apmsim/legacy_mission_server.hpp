#pragma once
// The mission protocol of APMrover2 2.4x (GCS_Mavlink.pde of ArduRover v2.43, before the AP_Mission
// library), for the rover2 firmware profile. What differs from mission_server.hpp, all from that source:
//  - MAVLink 1 and float items only: MISSION_REQUEST / MISSION_ITEM.
//  - MISSION_COUNT stores the new count at once (CMD_TOTAL is saved before any item arrives; slots not yet
//    written read as blank items) and clamps a count beyond capacity silently (no NO_SPACE). The board asks
//    for item 0 first (home included) and sends each MISSION_REQUEST to the system and component of the last
//    MISSION_REQUEST_LIST it answered (0/0 until one came since boot), not to the uploader.
//  - Patience: the expected item is asked for again 500 ms after the last request, and the board stops
//    listening 1 s after the last item (or count) arrived, silently (no MISSION_ACK).
//  - A MISSION_ITEM is checked before anything else: a frame other than MAV_FRAME_GLOBAL (0),
//    MAV_FRAME_MISSION (2) or MAV_FRAME_GLOBAL_RELATIVE_ALT (3) gets MISSION_ACK UNSUPPORTED_FRAME (2), a
//    command the 2.x firmware cannot store gets UNSUPPORTED (3); neither ends the transfer: the board keeps
//    asking for the same item until its 1 s patience runs out. Only NAV_WAYPOINT, NAV_RETURN_TO_LAUNCH,
//    NAV_TAKEOFF, CONDITION_DELAY/DISTANCE/CHANGE_ALT, DO_JUMP, DO_CHANGE_SPEED, DO_SET_HOME,
//    DO_SET_PARAMETER, DO_SET_RELAY/SERVO and DO_REPEAT_RELAY/SERVO are stored (NAV_LOITER_* are refused).
//  - Items are stored as the 2.x EEPROM keeps them (rover2_store()): location in 1e-7 degrees computed in
//    single precision and truncated, altitude in whole centimetres, one byte of param1, and for do- and
//    condition commands their other parameters in the location fields. A download (rover2_download()) gives
//    back only what was kept, adds the home altitude to a relative altitude, and answers an index past the
//    end with a blank item (command 0) rather than an error. Item 0 is whatever was uploaded there until the
//    board writes its home again at the next boot.
//  - MISSION_REQUEST_LIST abandons an upload in progress; there is one transfer state for every ground
//  station
//    (no DENIED). MISSION_CLEAR_ALL is always ACCEPTED, even in AUTO. MISSION_WRITE_PARTIAL_LIST must stay
//    within the stored items (no append); out of range it gets STATUSTEXT "flight plan update rejected" and
//    no MISSION_ACK. MISSION_SET_CURRENT is handed to the command processor and always answered with
//    MISSION_CURRENT (its command index).
//  - Only requests addressed to system 1 exactly are served (target 0 is not "broadcast" to 2.x).
#include <cstdint>
#include <functional>

#include "base/time.hpp"
#include "services/autopilot/mavlink/frame.hpp"
#include "services/autopilot/mavlink/messages.hpp"
#include "tools/apmsim/mission_server.hpp"
#include "tools/apmsim/mission_store.hpp"
#include "tools/apmsim/outbox.hpp"

namespace airseg::apmsim {

/// A stored rover2 item keeps the 2.x EEPROM fields in StoredItem: command = id, frame = 3 when the
/// altitude is relative else 0, param1 = p1 (one byte), lat_e7 / lon_e7 = lat / lng, alt = the raw alt field
/// (centimetres for places; for DO_CHANGE_SPEED the speed in whole m/s); param2..4 are not kept.
/// MAV_MISSION_ACCEPTED with the item, or a refusal (UNSUPPORTED_FRAME, UNSUPPORTED) and no item.
struct Rover2Stored {
    std::uint8_t result = 0;
    StoredItem item;
};
Rover2Stored rover2_store(const mavlink::MissionItem& m);
/// What a 2.x board sends for a stored item (the blank item for an index past the end).
mavlink::MissionItem rover2_download(const StoredItem& stored, std::int32_t home_alt_cm);
/// An empty EEPROM slot (CMD_BLANK).
StoredItem rover2_blank();

struct LegacyMissionHooks {
    /// The command processor's index (the `current` flag of downloads and MISSION_CURRENT).
    std::function<std::uint16_t()> command_index;
    /// MISSION_SET_CURRENT: change_command() of the command processor.
    std::function<void(std::uint16_t seq)> change_command;
    /// A MISSION_ITEM with current == 2 (the guided "go to"), accepted in any mode.
    std::function<void(const StoredItem& item)> guided_goto;
    /// The stored count or items changed.
    std::function<void()> changed;
    /// Home altitude in centimetres, added to relative altitudes in downloads.
    std::function<std::int32_t()> home_alt_cm;
};

class LegacyMissionServer {
  public:
    LegacyMissionServer(MissionStore& store, Outbox& out, LegacyMissionHooks hooks,
                        Duration rerequest = milliseconds(500), Duration give_up = seconds(1))
        : store_(store), out_(out), hooks_(std::move(hooks)), rerequest_(rerequest), give_up_(give_up) {}

    /// Handles a mission message; false if `frame` is not one the 2.x firmware serves.
    bool handle(const mavlink::Frame& frame, TimePoint now);
    void handle_timeout(TimePoint now);
    TimePoint poll_timeout() const;
    /// A reboot forgets the transfer and the last downloader.
    void reset() {
        receiving_ = false;
        dest_sysid_ = 0;
        dest_compid_ = 0;
    }
    bool receiving() const { return receiving_; }
    const MissionServerStats& stats() const { return stats_; }

  private:
    void on_item(const mavlink::Frame& f, const mavlink::MissionItem& m, TimePoint now);
    void request(TimePoint now);
    void ack(const mavlink::Frame& to, std::uint8_t result);
    void text(std::string_view message);

    MissionStore& store_;
    Outbox& out_;
    LegacyMissionHooks hooks_;
    Duration rerequest_;
    Duration give_up_;
    bool receiving_ = false;
    std::uint16_t request_i_ = 0;
    std::uint16_t request_last_ = 0;
    TimePoint last_heard_{};
    TimePoint last_request_{};
    std::uint8_t dest_sysid_ = 0;  // set by MISSION_REQUEST_LIST; where MISSION_REQUESTs go
    std::uint8_t dest_compid_ = 0;
    MissionServerStats stats_;
};

}  // namespace airseg::apmsim
